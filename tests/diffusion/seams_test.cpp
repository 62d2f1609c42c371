// The seam statistic (engine/diffusion/seams.cpp) on a flat grid split into two charts at x = 0.5:
// a linear field has the same jump per unit length across the border as inside (ratio 1 over
// the axis-aligned edges); a step at the border makes the border's P95 jump large; one chart has
// no border (ratio 0); sizes that do not fit are input errors.
#include "sdfkit/core/error.hpp"
#include "sdfkit/diffusion/seams.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace sdfkit::diffusion {
namespace {

// n × n vertices on [0, 1]², two triangles per cell; chart 0 left of x = 0.5, chart 1 right.
struct Grid {
  Mesh mesh;
  AtlasMapping mapping;
};
Grid grid(int n) {
  Grid g;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const float x = static_cast<float>(i) / static_cast<float>(n - 1), y = static_cast<float>(j) / static_cast<float>(n - 1);
      g.mesh.positions.emplace_back(x, y, 0.0f);
      g.mapping.vertex_chart.push_back(x < 0.5f ? 0u : 1u);
    }
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const auto v = static_cast<std::uint32_t>(j * n + i), un = static_cast<std::uint32_t>(n);
      g.mesh.triangles.push_back({v, v + 1, v + un + 1});
      g.mesh.triangles.push_back({v, v + un + 1, v + un});
    }
  return g;
}

TEST(Seams, LinearFieldHasNoSeamAndAStepHasOne) {
  const Grid g = grid(21);
  std::vector<float> linear, step;
  for (const glm::vec3& p : g.mesh.positions) {
    linear.push_back(2.0f * p.x);
    step.push_back(2.0f * p.x + (p.x < 0.5f ? 0.0f : 1.0f));
  }
  const SeamJumps s = seam_jumps(g.mesh, g.mapping, linear);
  // Edges: 20 · 21 horizontal + 20 · 21 vertical + 400 diagonal; the border is crossed by the
  // horizontal and diagonal edges of the column of cells at x = 0.45..0.5 (x = 0.5 is chart 1).
  EXPECT_EQ(s.border.size() + s.inside.size(), std::size_t{20 * 21 * 2 + 400});
  EXPECT_EQ(s.border.size(), std::size_t{21 + 20});
  // Horizontal edges jump by 2 per unit, vertical by 0, diagonals by 2 / sqrt 2; the P95 of both
  // sets is 2 (the horizontal edges are over 5 % of each).
  EXPECT_NEAR(quantile(s.inside, 0.95), 2.0, 1e-5);
  EXPECT_NEAR(seam_ratio(s), 1.0, 1e-5);
  EXPECT_NEAR(seam_ratio(g.mesh, g.mapping, linear), 1.0, 1e-5);
  // The step adds 1 over an edge of 1/20: 22 per unit across the border's horizontal edges.
  EXPECT_NEAR(seam_ratio(g.mesh, g.mapping, step), 11.0, 1e-3);
  AtlasMapping one = g.mapping;
  one.vertex_chart.assign(one.vertex_chart.size(), 0u);
  EXPECT_EQ(seam_ratio(g.mesh, one, step), 0.0);
  EXPECT_THROW(seam_jumps(g.mesh, g.mapping, std::vector<float>(3, 0.0f)), InputError);
  one.vertex_chart.pop_back();
  EXPECT_THROW(seam_jumps(g.mesh, one, linear), InputError);
}

TEST(Seams, QuantileIsTheRankedElement) {
  EXPECT_EQ(quantile({}, 0.5), 0.0);
  EXPECT_EQ(quantile({3.0, 1.0, 2.0, 5.0, 4.0}, 0.0), 1.0);
  EXPECT_EQ(quantile({3.0, 1.0, 2.0, 5.0, 4.0}, 0.5), 3.0);
  EXPECT_EQ(quantile({3.0, 1.0, 2.0, 5.0, 4.0}, 1.0), 5.0);
  EXPECT_EQ(quantile({3.0, 1.0, 2.0, 5.0, 4.0}, 0.95), 4.0);  // rank floor(0.95 · 4) = 3
}

}  // namespace
}  // namespace sdfkit::diffusion

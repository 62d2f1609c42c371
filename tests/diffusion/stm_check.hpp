#pragma once
// Properties every skeleton texture mapping must have, whatever the charts (stm_test.cpp and
// stm_real_mesh_test.cpp): every vertex in a chart and inside its rectangle, rectangles inside
// the atlas and apart by the gutter, atlas triangles inside their rectangle (wrapping charts:
// contiguous, less than a width across), no triangle stretched, every face drawn in the chart
// of each of its vertices, finite quality numbers.

#include "sdfkit/diffusion/stm.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

namespace sdfkit::test {

inline void expect_valid_stm(const Mesh& mesh, const diffusion::Stm& stm, const diffusion::StmOptions& options = {}) {
  using diffusion::Chart;
  const diffusion::AtlasMapping& m = stm.mapping;
  const std::size_t V = mesh.positions.size(), C = m.charts.size();
  ASSERT_EQ(m.size, options.atlas_size);
  ASSERT_EQ(m.gutter, options.gutter);
  ASSERT_EQ(m.vertex_chart.size(), V);
  ASSERT_EQ(m.vertex_uv.size(), V);
  ASSERT_EQ(stm.quality.charts.size(), C);
  ASSERT_GT(C, 0u);
  const float S = static_cast<float>(m.size), G = static_cast<float>(m.gutter);
  // Rectangles: inside the atlas with the gutter around, pairwise apart by the gutter.
  for (std::size_t a = 0; a < C; ++a) {
    const Chart& ca = m.charts[a];
    ASSERT_GT(ca.width, 0u);
    ASSERT_GT(ca.height, 0u);
    EXPECT_GE(ca.x0, m.gutter);
    EXPECT_GE(ca.y0, m.gutter);
    EXPECT_LE(ca.x0 + ca.width + m.gutter, m.size);
    EXPECT_LE(ca.y0 + ca.height + m.gutter, m.size);
    EXPECT_TRUE(std::isfinite(ca.texels_per_unit) && ca.texels_per_unit > 0);
    for (std::size_t b = a + 1; b < C; ++b) {
      const Chart& cb = m.charts[b];
      const bool apart = ca.x0 + ca.width + m.gutter <= cb.x0 || cb.x0 + cb.width + m.gutter <= ca.x0 ||
                         ca.y0 + ca.height + m.gutter <= cb.y0 || cb.y0 + cb.height + m.gutter <= ca.y0;
      ASSERT_TRUE(apart) << "charts " << a << " and " << b << " overlap or touch inside the gutter";
    }
  }
  const auto inside = [&](const Chart& c, glm::vec2 q) {
    return q.x >= static_cast<float>(c.x0) && q.x <= static_cast<float>(c.x0 + c.width) &&
           q.y >= static_cast<float>(c.y0) && q.y <= static_cast<float>(c.y0 + c.height);
  };
  for (std::size_t v = 0; v < V; ++v) {
    ASSERT_LT(m.vertex_chart[v], C);
    ASSERT_TRUE(inside(m.charts[m.vertex_chart[v]], m.vertex_uv[v]))
        << "vertex " << v << " at " << m.vertex_uv[v].x << "," << m.vertex_uv[v].y << " outside chart "
        << m.vertex_chart[v];
  }
  (void)S, (void)G;
  // The blended read-back's samples (AtlasMapping::samples): only with a band and blending; sorted
  // by vertex, every vertex once in its own chart at its own uv, other charts at most once, every
  // weight in (0, 1], every uv inside its chart.
  if (options.overlap > 0 && options.blend) {
    ASSERT_GE(m.samples.size(), V);
    std::size_t i = 0, borrowing = 0;
    for (std::uint32_t v = 0; v < V; ++v) {
      std::set<std::uint32_t> seen;
      int own = 0;
      bool twice = false;
      ASSERT_LT(i, m.samples.size());
      ASSERT_EQ(m.samples[i].vertex, v);
      for (; i < m.samples.size() && m.samples[i].vertex == v; ++i) {
        const diffusion::VertexSample& s = m.samples[i];
        ASSERT_LT(s.chart, C);
        twice = twice || !seen.insert(s.chart).second;
        EXPECT_TRUE(inside(m.charts[s.chart], s.uv)) << "vertex " << v << "'s sample outside chart " << s.chart;
        EXPECT_GT(s.weight, 0.0f);
        EXPECT_LE(s.weight, 1.0f);
        own += s.chart == m.vertex_chart[v] && s.uv == m.vertex_uv[v];
      }
      // A vertex reads its own chart at its own uv and each chart at most once, unless that read
      // does not see its surroundings (StmQuality::dropped_own_reads): then the other charts
      // covering it, or its nearest vertices' reads.
      if (own == 0) {
        ++borrowing;
        continue;
      }
      ASSERT_EQ(own, 1) << "vertex " << v;
      EXPECT_FALSE(twice) << "vertex " << v << " samples a chart twice";
    }
    EXPECT_EQ(i, m.samples.size());
    EXPECT_EQ(borrowing, stm.quality.dropped_own_reads);
    EXPECT_LE(stm.quality.borrowed_vertices, stm.quality.dropped_own_reads);
  } else {
    EXPECT_TRUE(m.samples.empty());
  }
  // Atlas triangles.
  std::vector<std::set<std::uint32_t>> face_charts(mesh.triangles.size());
  const double tpu = stm.quality.texels_per_unit;
  ASSERT_TRUE(std::isfinite(tpu) && tpu > 0);
  double worst_stretch = 0;
  for (const diffusion::AtlasTriangle& t : m.triangles) {
    ASSERT_LT(t.chart, C);
    ASSERT_LT(t.face, mesh.triangles.size());
    face_charts[t.face].insert(t.chart);
    const Chart& c = m.charts[t.chart];
    float xmin = 1e30f, xmax = -1e30f;
    for (const glm::vec2& q : t.uv) {
      ASSERT_TRUE(std::isfinite(q.x) && std::isfinite(q.y));
      EXPECT_GE(q.y, static_cast<float>(c.y0));
      EXPECT_LE(q.y, static_cast<float>(c.y0 + c.height));
      xmin = std::min(xmin, q.x), xmax = std::max(xmax, q.x);
    }
    if (c.wraps_x) {
      EXPECT_LT(xmax - xmin, static_cast<float>(c.width)) << "face " << t.face;
      EXPECT_GT(xmax, static_cast<float>(c.x0));
      EXPECT_LT(xmin, static_cast<float>(c.x0 + c.width));
    } else {
      EXPECT_GE(xmin, static_cast<float>(c.x0));
      EXPECT_LE(xmax, static_cast<float>(c.x0 + c.width));
    }
    const Triangle& f = mesh.triangles[t.face];
    double model = 0, texel = 0;
    for (int k = 0; k < 3; ++k) {
      model = std::max(model, static_cast<double>(glm::length(mesh.positions[f[k]] - mesh.positions[f[(k + 1) % 3]])));
      texel = std::max(texel, static_cast<double>(glm::length(t.uv[k] - t.uv[(k + 1) % 3])));
    }
    // max_stretch, the rounding of a wrapping chart's width to whole texels (≤ 1/6 at 3 texels)
    // and half a texel of float and rectangle rounding.
    const double bound = options.max_stretch * (7.0 / 6.0) * model * tpu + 0.5;
    EXPECT_LE(texel, bound) << "face " << t.face << " stretched in chart " << t.chart;
    if (model * tpu > 1) worst_stretch = std::max(worst_stretch, texel / (model * tpu));
  }
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
    for (std::uint32_t v : mesh.triangles[f])
      ASSERT_TRUE(face_charts[f].count(m.vertex_chart[v])) << "face " << f << " is not drawn in the chart of vertex " << v;
  // Quality numbers.
  const diffusion::StmQuality& q = stm.quality;
  EXPECT_GT(q.atlas_used, 0.0);
  EXPECT_LE(q.atlas_used, 1.0);
  EXPECT_GT(q.atlas_covered, 0.0);
  EXPECT_LE(q.atlas_covered, q.atlas_used);
  for (const diffusion::ChartQuality& cq : q.charts) {
    EXPECT_TRUE(std::isfinite(cq.area_distortion.mean) && std::isfinite(cq.area_distortion.max));
    EXPECT_TRUE(std::isfinite(cq.angle_distortion.mean));
    EXPECT_GE(cq.area_distortion.max, cq.area_distortion.p95);
  }
  EXPECT_EQ(q.bone_charts + q.joint_charts + q.sheet_charts, C);
}

}  // namespace sdfkit::test

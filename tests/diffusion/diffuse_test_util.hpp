#pragma once
// Test-side tools for texture-space diffusion: intrinsic heat diffusion (the library's,
// sdfkit/diffusion/heat.hpp), analytic shapes with mappings built by
// hand (a cylinder as one wrapping chart or as overlapping non-wrapping charts, a box as one chart
// per side). The seam statistic is the library's (sdfkit/diffusion/seams.hpp).

#include "sdfkit/core/mesh.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/diffusion/atlas.hpp"
#include "sdfkit/diffusion/heat.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <span>
#include <utility>
#include <vector>

namespace sdfkit::test {

// Heat flow for time t = sigma² / 2: the library's reference (sdfkit/diffusion/heat.hpp, `steps`
// implicit steps with the cotangent Laplacian and the lumped mass). The one reference of the
// tests and of sdfkit-seam-bench: diffusion::kHeatSteps steps unless a test asks for others.
inline std::vector<float> heat_diffusion(const Mesh& mesh, std::span<const float> u0, double sigma, int steps = diffusion::kHeatSteps) {
  return diffusion::heat_diffusion(mesh, u0, sigma, steps);
}

// Lumped (barycentric) vertex areas: a third of each incident triangle's area, the heat
// reference's mass matrix.
inline std::vector<double> lumped_areas(const Mesh& mesh) {
  std::vector<double> area(mesh.positions.size(), 0.0);
  for (const Triangle& t : mesh.triangles) {
    const glm::dvec3 a(mesh.positions[t[0]]), b(mesh.positions[t[1]]), c(mesh.positions[t[2]]);
    const double third = glm::length(glm::cross(b - a, c - a)) / 6.0;
    for (std::uint32_t v : t) area[v] += third;
  }
  return area;
}

// An open cylinder of radius r and height h around z (shapes::open_cylinder: vertex (i, j) =
// j * segments + i at angle 2 pi i / segments, height j * h / stacks).
inline Mesh open_cylinder(float r, float h, int segments, int stacks) { return shapes::open_cylinder(r, h, segments, stacks); }

struct CylinderGrid {
  float r = 1.0f, h = 4.0f;
  int segments = 64, stacks = 40;
  std::uint32_t texels_per_column = 4;  // atlas texels per column around
  float texels_per_unit() const {
    return static_cast<float>(texels_per_column * static_cast<std::uint32_t>(segments)) / (2.0f * std::numbers::pi_v<float> * r);
  }
};

// The cylinder as one wrapping chart at (x0, y0): x = angle, y = height, isometric.
inline diffusion::AtlasMapping cylinder_wrapping_mapping(const Mesh& m, const CylinderGrid& g, std::uint32_t size,
                                                         std::uint32_t x0 = 2, std::uint32_t y0 = 2) {
  diffusion::AtlasMapping a;
  a.size = size;
  const float tpu = g.texels_per_unit();
  diffusion::Chart c;
  c.kind = diffusion::Chart::Kind::Bone;
  c.x0 = x0;
  c.y0 = y0;
  c.width = g.texels_per_column * static_cast<std::uint32_t>(g.segments);
  c.height = static_cast<std::uint32_t>(std::ceil(g.h * tpu)) + 1;
  c.wraps_x = true;
  c.texels_per_unit = tpu;
  a.charts.push_back(c);
  const auto uv = [&](std::uint32_t v) {
    const int i = static_cast<int>(v) % g.segments, j = static_cast<int>(v) / g.segments;
    return glm::vec2(static_cast<float>(x0) + static_cast<float>(i * static_cast<int>(g.texels_per_column)),
                     static_cast<float>(y0) + 0.5f + tpu * g.h * static_cast<float>(j) / static_cast<float>(g.stacks));
  };
  for (std::uint32_t f = 0; f < m.face_count(); ++f) {
    diffusion::AtlasTriangle t;
    t.chart = 0;
    t.face = f;
    for (int k = 0; k < 3; ++k) t.uv[k] = uv(m.triangles[f][static_cast<std::size_t>(k)]);
    a.triangles.push_back(t);
  }
  for (std::uint32_t v = 0; v < m.vertex_count(); ++v) {
    a.vertex_chart.push_back(0);
    a.vertex_uv.push_back(uv(v));
  }
  return a;
}

// The cylinder cut into `parts` non-wrapping charts around, each carrying its own columns and
// `overlap` columns of its neighbours' triangles on each side (duplicated), side by side in x.
inline diffusion::AtlasMapping cylinder_split_mapping(const Mesh& m, const CylinderGrid& g, std::uint32_t size,
                                                      int parts, int overlap) {
  diffusion::AtlasMapping a;
  a.size = size;
  a.gutter = 2;
  const float tpu = g.texels_per_unit();
  const int per = g.segments / parts;
  const int cols = per + 2 * overlap;
  const auto tc = static_cast<int>(g.texels_per_column);
  std::uint32_t x = a.gutter;
  for (int p = 0; p < parts; ++p) {
    diffusion::Chart c;
    c.x0 = x;
    c.y0 = a.gutter;
    c.width = static_cast<std::uint32_t>(cols * tc + 1);
    c.height = static_cast<std::uint32_t>(std::ceil(g.h * tpu)) + 1;
    c.texels_per_unit = tpu;
    a.charts.push_back(c);
    x += c.width + a.gutter;
  }
  // Column i (0..segments-1) as seen from chart p: offset from the chart's first column.
  const auto local_col = [&](int p, int i) {
    int d = i - (p * per - overlap);
    d = ((d % g.segments) + g.segments) % g.segments;
    return d;  // 0..segments-1; inside the chart when <= cols
  };
  const auto uv_in = [&](int p, int i, int j) {
    const auto& c = a.charts[static_cast<std::size_t>(p)];
    return glm::vec2(static_cast<float>(c.x0) + 0.5f + static_cast<float>(local_col(p, i) * tc),
                     static_cast<float>(c.y0) + 0.5f + tpu * g.h * static_cast<float>(j) / static_cast<float>(g.stacks));
  };
  for (std::uint32_t f = 0; f < m.face_count(); ++f) {
    // The quad column of the face: its smallest i, across the seam the last one.
    int is[3], js[3];
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<int>(m.triangles[f][static_cast<std::size_t>(k)]);
      is[k] = v % g.segments;
      js[k] = v / g.segments;
    }
    const int lo = *std::min_element(is, is + 3), hi = *std::max_element(is, is + 3);
    const int col = (hi - lo > 1) ? hi : lo;
    for (int p = 0; p < parts; ++p) {
      const int d = local_col(p, col);
      if (d + 1 > cols) continue;  // the quad's right column must lie in the chart too
      diffusion::AtlasTriangle t;
      t.chart = static_cast<std::uint32_t>(p);
      t.face = f;
      for (int k = 0; k < 3; ++k) t.uv[k] = uv_in(p, is[k], js[k]);
      a.triangles.push_back(t);
    }
  }
  for (std::uint32_t v = 0; v < m.vertex_count(); ++v) {
    const int i = static_cast<int>(v) % g.segments, j = static_cast<int>(v) / g.segments;
    const int p = i / per;
    a.vertex_chart.push_back(static_cast<std::uint32_t>(p));
    a.vertex_uv.push_back(uv_in(p, i, j));
  }
  return a;
}

inline double rms_difference(std::span<const float> a, std::span<const float> b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += (static_cast<double>(a[i]) - b[i]) * (static_cast<double>(a[i]) - b[i]);
  return std::sqrt(s / static_cast<double>(std::max<std::size_t>(a.size(), 1)));
}

// A smooth wave over the bounding box plus seeded Gaussian noise (σ 0.05): a field whose
// diffusion the heat-agreement tests and sdfkit-seam-bench compare.
inline std::vector<float> wave_field(const Mesh& m) {
  const Aabb box = bounding_box(m.positions);
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  std::vector<float> u(m.vertex_count());
  for (std::size_t v = 0; v < u.size(); ++v) {
    const glm::vec3 p = (m.positions[v] - box.min) / box.diagonal();
    u[v] = 1.0f + 0.5f * std::sin(6.0f * p.x) * std::cos(5.0f * p.y) + noise(rng);
  }
  return u;
}

}  // namespace sdfkit::test

// Skeleton texture mapping from skeletons the library extracts (Embree reference SDF): a
// capsule (the extracted skeleton, not the hand-made one, still gives a near-isometric bone
// chart) and real CGAL meshes (a quadruped, a human): every mapping property holds and the
// distortion is finite and bounded.
#include "sdfkit/core/error.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/diffusion/stm.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/reference/embree_backend.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <vector>

#include "analytic.hpp"
#include "stm_check.hpp"

using namespace sdfkit;
namespace sk = sdfkit::skeleton;
namespace dif = sdfkit::diffusion;

namespace {

sk::Skeleton extract(const Mesh& mesh) {
  reference::EmbreeBackend backend;
  return sk::extract(mesh, &backend, {}, {});
}

}  // namespace

TEST(StmExtracted, CapsuleBoneChartIsNearIsometric) {
  const Mesh mesh = shapes::capsule(0.5f, 3.0f, 48, 40);
  const dif::Stm stm = dif::build_stm(mesh, extract(mesh));
  test::expect_valid_stm(mesh, stm);
  EXPECT_GE(stm.quality.bone_charts, 1u);
  EXPECT_GT(stm.quality.bone_vertex_share, 0.5);
  // The largest bone chart carries the cylinder: its area distortion stays near 1 (the
  // extracted polyline wobbles around the axis by a few % of the radius).
  const dif::ChartQuality* bone = nullptr;
  for (const dif::ChartQuality& c : stm.quality.charts)
    if (c.kind == dif::Chart::Kind::Bone && (!bone || c.area > bone->area)) bone = &c;
  ASSERT_NE(bone, nullptr);
  EXPECT_GT(bone->area, 0.5 * 2 * M_PI * 0.5 * 3.0);
  EXPECT_NEAR(bone->area_distortion.mean, 1.0, 0.1);
  EXPECT_LT(bone->angle_distortion.p95, 1.25);
}

TEST(StmExtracted, QuadrupedHasFiniteBoundedDistortion) {
  const Mesh mesh = io::load_asset(test::data_mesh("camel.off")).mesh;
  const dif::Stm stm = dif::build_stm(mesh, extract(mesh));
  test::expect_valid_stm(mesh, stm);
  EXPECT_GE(stm.quality.bone_charts, 6u) << "legs, neck, tail";
  // Measured: 45 % of the vertices in bone charts (the body is one planar joint region), angle
  // distortion p95 4.1 over all charts.
  EXPECT_GT(stm.quality.bone_vertex_share, 0.4);
  EXPECT_TRUE(std::isfinite(stm.quality.area_distortion.max));
  EXPECT_LT(stm.quality.angle_distortion.p95, 6.0);
  EXPECT_GT(stm.quality.area_distortion.mean, 0.5);
  EXPECT_LT(stm.quality.area_distortion.mean, 2.0);
}

TEST(StmExtracted, HumanHasFiniteBoundedDistortion) {
  const Mesh mesh = io::load_asset(test::data_mesh("man.off")).mesh;
  const dif::Stm stm = dif::build_stm(mesh, extract(mesh));
  test::expect_valid_stm(mesh, stm);
  EXPECT_GE(stm.quality.bone_charts, 4u);
  EXPECT_TRUE(std::isfinite(stm.quality.area_distortion.max));
  EXPECT_LT(stm.quality.angle_distortion.p95, 4.0);
}

// The overlap band (StmOptions::overlap) on CGAL's camel: every mapping property still holds,
// the vertices read from the same charts as without it, the charts carry more triangles, every
// band triangle lies within the band (its nearest corner no further from the chart's vertices
// than the band, straight-line distance being a lower bound of the distance along the surface)
// and keeps the orientation of its chart's own faces (no fold), under 1 % of the covered texels
// carry two triangles, and a bad band is a usage error.
TEST(StmExtracted, OverlapBandStaysInReachAndDoesNotFold) {
  const Mesh mesh = io::load_asset(test::data_mesh("camel.off")).mesh;
  const sk::Skeleton skel = sk::extract(mesh, nullptr, {}, {});
  double edge = 0;
  for (const Triangle& t : mesh.triangles) edge += glm::length(mesh.positions[t[1]] - mesh.positions[t[0]]);
  edge /= static_cast<double>(mesh.triangles.size());
  dif::StmOptions options;
  options.overlap = 6 * edge;
  const dif::Stm plain = dif::build_stm(mesh, skel), band = dif::build_stm(mesh, skel, options);
  test::expect_valid_stm(mesh, band, options);
  EXPECT_EQ(band.mapping.vertex_chart, plain.mapping.vertex_chart);
  EXPECT_GT(band.mapping.triangles.size(), 2 * plain.mapping.triangles.size());
  const auto& m = band.mapping;
  std::vector<std::vector<std::uint32_t>> verts(m.charts.size());
  for (std::uint32_t v = 0; v < m.vertex_chart.size(); ++v) verts[m.vertex_chart[v]].push_back(v);
  const auto area2 = [](const dif::AtlasTriangle& t) {
    return (t.uv[1].x - t.uv[0].x) * (t.uv[2].y - t.uv[0].y) - (t.uv[1].y - t.uv[0].y) * (t.uv[2].x - t.uv[0].x);
  };
  std::vector<int> orientation(m.charts.size(), 0);
  for (const dif::AtlasTriangle& t : m.triangles) {
    const Triangle& f = mesh.triangles[t.face];
    if (m.vertex_chart[f[0]] == t.chart && m.vertex_chart[f[1]] == t.chart && m.vertex_chart[f[2]] == t.chart)
      orientation[t.chart] += area2(t) > 0 ? 1 : -1;
  }
  std::size_t band_triangles = 0;
  for (const dif::AtlasTriangle& t : m.triangles) {
    const Triangle& f = mesh.triangles[t.face];
    if (m.vertex_chart[f[0]] == t.chart || m.vertex_chart[f[1]] == t.chart || m.vertex_chart[f[2]] == t.chart) continue;
    ++band_triangles;
    double nearest = std::numeric_limits<double>::infinity();
    for (std::uint32_t c : f)
      for (std::uint32_t v : verts[t.chart]) nearest = std::min<double>(nearest, glm::length(mesh.positions[c] - mesh.positions[v]));
    EXPECT_LE(nearest, options.overlap * (1 + 1e-6)) << "face " << t.face << " in chart " << t.chart;
    // (float texel corners: a sliver's area may round to a few 1e-5 texel² of either sign)
    EXPECT_GT(area2(t) * (orientation[t.chart] >= 0 ? 1.0f : -1.0f), -1e-3f) << "face " << t.face << " folds in chart " << t.chart;
  }
  EXPECT_GT(band_triangles, mesh.triangles.size());
  // Nor does a band lay its chart over itself (non-wrapping charts; a wrapping bone chart may still
  // fold at a sharp bend): few texels carry two triangles (measured 0.094 %).
  std::printf("camel, band 6 edges: %.3f %% of the covered texels carry two triangles, %zu of %zu vertices lose their own read, %zu borrow\n", 100.0 * band.quality.overlap, band.quality.dropped_own_reads, mesh.positions.size(), band.quality.borrowed_vertices);
  EXPECT_LT(band.quality.overlap, 0.01);
  for (double bad : {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    dif::StmOptions o;
    o.overlap = bad;
    EXPECT_THROW(dif::build_stm(mesh, skel, o), UsageError) << bad;
  }
}

// A bone chart's map (angle around the bone, arc length along it) is one-to-one: no texel is
// covered by two of its own faces (those with two or three corners in it), counted by
// rasterizing them at the texel centres (wrapping charts also one width to either side). CGAL's
// rotor is a hub with blades that the bone's map laid onto the same angles and arc lengths as the
// hub (3.2 % of the covered texels twice, before build_stm demoted the faces that overlap).
TEST(StmExtracted, BoneChartsAreOneToOne) {
  for (const char* name : {"rotor.off", "camel.off", "elephant.off"}) {
    const Mesh mesh = io::load_asset(test::data_mesh(name)).mesh;
    const dif::Stm stm = dif::build_stm(mesh, sk::extract(mesh, nullptr, {}, {}));
    test::expect_valid_stm(mesh, stm);
    const dif::AtlasMapping& m = stm.mapping;
    std::vector<std::uint8_t> count(static_cast<std::size_t>(m.size) * m.size, 0);
    std::size_t bone_faces = 0, twice = 0;
    for (const dif::AtlasTriangle& t : m.triangles) {
      const dif::Chart& ch = m.charts[t.chart];
      if (ch.kind != dif::Chart::Kind::Bone) continue;
      int own = 0;
      for (std::uint32_t v : mesh.triangles[t.face]) own += m.vertex_chart[v] == t.chart;
      if (own < 2) continue;
      ++bone_faces;
      for (int shift = ch.wraps_x ? -1 : 0; shift <= (ch.wraps_x ? 1 : 0); ++shift) {
        glm::dvec2 q[3];
        for (int k = 0; k < 3; ++k) q[k] = glm::dvec2(t.uv[k]) + glm::dvec2(shift * double(ch.width), 0.0);
        const auto cross = [](glm::dvec2 a, glm::dvec2 b, glm::dvec2 p) { return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x); };
        const double den = cross(q[0], q[1], q[2]);
        if (den == 0) continue;
        const auto first = [](double lo, std::uint32_t begin) { return std::max<long>(begin, std::lround(std::ceil(lo - 0.5))); };
        const auto last = [](double hi, std::uint32_t end) { return std::min<long>(long(end) - 1, std::lround(std::floor(hi - 0.5))); };
        for (long y = first(std::min({q[0].y, q[1].y, q[2].y}), ch.y0); y <= last(std::max({q[0].y, q[1].y, q[2].y}), ch.y0 + ch.height); ++y)
          for (long x = first(std::min({q[0].x, q[1].x, q[2].x}), ch.x0); x <= last(std::max({q[0].x, q[1].x, q[2].x}), ch.x0 + ch.width); ++x) {
            const glm::dvec2 p(x + 0.5, y + 0.5);
            const double w0 = cross(q[1], q[2], p) / den, w1 = cross(q[2], q[0], p) / den, w2 = 1 - w0 - w1;
            if (w0 < 0 || w1 < 0 || w2 <= 0) continue;  // half-open: a centre on a shared edge counts once
            std::uint8_t& k = count[static_cast<std::size_t>(y) * m.size + static_cast<std::size_t>(x)];
            twice += k == 1;
            if (k < 255) ++k;
          }
      }
    }
    std::printf("%s: %zu faces in bone charts, %zu texels covered twice by them\n", name, bone_faces, twice);
    EXPECT_GT(bone_faces, 0u) << name;
    EXPECT_EQ(twice, 0u) << name;
  }
}

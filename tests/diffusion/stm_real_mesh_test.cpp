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
  std::printf("camel, band 6 edges: %.3f %% of the covered texels carry two triangles\n", 100.0 * band.quality.overlap);
  EXPECT_LT(band.quality.overlap, 0.01);
  for (double bad : {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    dif::StmOptions o;
    o.overlap = bad;
    EXPECT_THROW(dif::build_stm(mesh, skel, o), UsageError) << bad;
  }
}

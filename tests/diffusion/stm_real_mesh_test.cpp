// Skeleton texture mapping from skeletons the library extracts (Embree reference SDF): a
// capsule (the extracted skeleton, not the hand-made one, still gives a near-isometric bone
// chart) and real CGAL meshes (a quadruped, a human): every mapping property holds and the
// distortion is finite and bounded.
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/diffusion/stm.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/reference/embree_backend.hpp"

#include <gtest/gtest.h>

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

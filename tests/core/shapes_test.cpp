#include "analytic.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/core/topology.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>

using namespace sdfkit;


TEST(Shapes, OutwardOrientedWithTheRightVolume) {
  const double pi = M_PI;
  EXPECT_NEAR(test::signed_volume(shapes::sphere(2, 96, 48)), 4.0 / 3.0 * pi * 8, 0.01 * 4 / 3. * pi * 8);
  EXPECT_NEAR(test::signed_volume(shapes::icosphere(2, 4)), 4.0 / 3.0 * pi * 8, 0.01 * 4 / 3. * pi * 8);
  EXPECT_NEAR(test::signed_volume(shapes::capped_cylinder(1, 4, 128, 4, 3)), pi * 4, 0.01 * pi * 4);
  EXPECT_NEAR(test::signed_volume(shapes::capsule(1, 2, 96, 4)), pi * 2 + 4.0 / 3 * pi, 0.02 * pi * 3.3);
  EXPECT_NEAR(test::signed_volume(shapes::torus(3, 1, 128, 64)), 2 * pi * pi * 3, 0.01 * 2 * pi * pi * 3);
  EXPECT_NEAR(test::signed_volume(shapes::box(1, 2, 3, 5)), 6.0, 1e-4);
}

TEST(Shapes, VerticesLieOnTheImplicitSurface) {
  for (const auto& p : shapes::sphere(2, 32, 16).positions) EXPECT_NEAR(shapes::sphere_sdf(p, 2), 0, 1e-5);
  for (const auto& p : shapes::torus(3, 1, 32, 16).positions) EXPECT_NEAR(shapes::torus_sdf(p, 3, 1), 0, 1e-5);
  for (const auto& p : shapes::capped_cylinder(1, 4, 32, 3, 2).positions)
    EXPECT_NEAR(shapes::capped_cylinder_sdf(p, 1, 4), 0, 1e-5);
  for (const auto& p : shapes::capsule(1, 2, 32, 3).positions)
    EXPECT_NEAR(shapes::capsule_sdf(p, 1, 2), 0, 1e-5);
  for (const auto& p : shapes::box(1, 2, 3, 3).positions)
    EXPECT_NEAR(shapes::box_sdf(p, {1, 2, 3}), 0, 1e-5);
}

TEST(Shapes, SweptTubeIsClosedAndGrowsFromD0ToD1) {
  const auto tube = shapes::swept_tube(2, 20, 120, 32);
  const MeshReport r = analyze(tube.mesh);
  EXPECT_EQ(r.boundary_edges, 0u);
  EXPECT_EQ(r.non_manifold_edges, 0u);
  EXPECT_EQ(r.components, 1u);
  EXPECT_GT(test::signed_volume(tube.mesh), 0.0);
  float lo = 1e9f, hi = 0;
  for (float d : tube.true_diameter) {
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  EXPECT_FLOAT_EQ(lo, 2.0f);
  EXPECT_FLOAT_EQ(hi, 20.0f);
}

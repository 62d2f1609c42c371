// The procedural skeleton models: closed, manifold, outward, with the volume they should have.

#include "analytic.hpp"

#include "sdfkit/core/topology.hpp"
#include "sdfkit/skeleton/models.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>

using namespace sdfkit;
namespace models = sdfkit::skeleton::models;

namespace {


void expect_closed_manifold(const Mesh& m, std::size_t components = 1) {
  const MeshReport r = analyze(m);
  EXPECT_EQ(r.boundary_edges, 0u);
  EXPECT_EQ(r.non_manifold_edges, 0u);
  EXPECT_EQ(r.degenerate_faces, 0u);
  EXPECT_EQ(r.components, components);
}

// Euler characteristic V - E + F of a closed mesh = 2 - 2 genus (per component).
int euler(const Mesh& m) {
  const MeshReport r = analyze(m);
  const Adjacency a = vertex_adjacency(m);
  return static_cast<int>(r.vertices) - static_cast<int>(a.indices.size() / 2) +
         static_cast<int>(r.faces);
}

}  // namespace

TEST(SkeletonModels, CShapeIsAClosedBarWithTheBandArea) {
  const auto c = models::c_shape(0.6f, 270.0f, 0.2f, 3.0f, 0.1f);
  expect_closed_manifold(c.mesh);
  EXPECT_EQ(euler(c.mesh), 2);
  // Cross-section: an annular sector of mean radius 0.6, thickness 0.2, 270 degrees.
  const double expected = 0.2 * 0.6 * 1.5 * M_PI * 3.0;
  EXPECT_NEAR(test::signed_volume(c.mesh), expected, 0.01 * expected);
}

TEST(SkeletonModels, SShapeIsAClosedBarWithTheBandArea) {
  const auto s = models::s_shape(0.5f, 225.0f, 0.2f, 3.0f, 0.1f);
  expect_closed_manifold(s.mesh);
  EXPECT_EQ(euler(s.mesh), 2);
  const double expected = 0.2 * 2.0 * 0.5 * (225.0 * M_PI / 180.0) * 3.0;
  EXPECT_NEAR(test::signed_volume(s.mesh), expected, 0.01 * expected);
}

TEST(SkeletonModels, StarIsASphereTopologyOnItsImplicitSurface) {
  const auto star = models::five_armed_star();
  expect_closed_manifold(star.mesh);
  EXPECT_EQ(euler(star.mesh), 2);
  EXPECT_GT(test::signed_volume(star.mesh), 0.0);
  for (const auto& p : star.mesh.positions) EXPECT_NEAR(star.fn(p), 0.0f, 2e-3f);
}

TEST(SkeletonModels, Genus2HasEulerCharacteristicMinusTwo) {
  const auto g = models::genus2();
  expect_closed_manifold(g.mesh);
  EXPECT_EQ(euler(g.mesh), -2);
  EXPECT_GT(test::signed_volume(g.mesh), 0.0);
  for (const auto& p : g.mesh.positions) EXPECT_NEAR(g.fn(p), 0.0f, 2e-3f);
}

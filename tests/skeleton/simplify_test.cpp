// The proxy simplifier (quadric edge collapses with the link condition) held to the topology
// it must keep: closed, edge-manifold, consistently oriented, no degenerate or duplicate faces,
// the same components and genus (Euler characteristic), a total vertex map, and a surface that
// stays near the input's.

#include "simplify.hpp"

#include "analytic.hpp"

#include "sdfkit/core/shapes.hpp"
#include "sdfkit/core/topology.hpp"
#include "sdfkit/skeleton/models.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>

using namespace sdfkit;
namespace detail = sdfkit::skeleton::detail;
namespace models = sdfkit::skeleton::models;

namespace {

// V - E + F of a mesh, counting undirected edges.
long euler_characteristic(const Mesh& m) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (const Triangle& t : m.triangles)
    for (int k = 0; k < 3; ++k) edges.insert({std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])});
  return static_cast<long>(m.positions.size()) - static_cast<long>(edges.size()) +
         static_cast<long>(m.triangles.size());
}

// Everything the contraction needs from a proxy of `input`, and the vertex map's totality.
void expect_valid_proxy(const Mesh& input, const detail::Simplified& s, std::size_t target) {
  const Mesh& m = s.mesh;
  const MeshReport before = analyze(input), after = analyze(m);
  EXPECT_EQ(after.boundary_edges, 0u);
  EXPECT_EQ(after.non_manifold_edges, 0u);
  EXPECT_EQ(after.degenerate_faces, 0u);
  EXPECT_EQ(after.isolated_vertices, 0u);
  EXPECT_EQ(after.components, before.components);
  EXPECT_EQ(euler_characteristic(m), euler_characteristic(input));  // same genus per component
  EXPECT_LE(m.positions.size(), target);
  EXPECT_LT(m.triangles.size(), input.triangles.size());
  // Consistent orientation: every directed edge once (its twin belongs to the other face).
  std::set<std::pair<std::uint32_t, std::uint32_t>> directed;
  for (const Triangle& t : m.triangles)
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(directed.insert({t[k], t[(k + 1) % 3]}).second);
  // No two faces on the same three vertices.
  std::set<Triangle> sorted;
  for (Triangle t : m.triangles) {
    std::sort(t.begin(), t.end());
    EXPECT_TRUE(sorted.insert(t).second);
  }
  // The map is total and onto, and local: every input vertex lies within two mean proxy edge
  // lengths of the proxy vertex it went to.
  ASSERT_EQ(s.vertex_map.size(), input.positions.size());
  std::vector<int> hit(m.positions.size(), 0);
  double edge = 0.0;
  for (const Triangle& t : m.triangles)
    for (int k = 0; k < 3; ++k) edge += glm::length(m.positions[t[k]] - m.positions[t[(k + 1) % 3]]);
  edge /= 3.0 * static_cast<double>(m.triangles.size());
  float farthest = 0.0f;
  for (std::size_t k = 0; k < input.positions.size(); ++k) {
    ASSERT_LT(s.vertex_map[k], m.positions.size());
    ++hit[s.vertex_map[k]];
    farthest = std::max(farthest, glm::length(input.positions[k] - m.positions[s.vertex_map[k]]));
  }
  std::printf("proxy %zu -> %zu vertices: farthest input vertex %.2f mean proxy edges from its proxy vertex\n",
              input.positions.size(), m.positions.size(), farthest / edge);
  EXPECT_LT(farthest, 2.0 * edge);
  for (int h : hit) EXPECT_GT(h, 0);
  // The enclosed volume stays close: a shape-preserving simplification, not a collapse.
  EXPECT_NEAR(test::signed_volume(m) / test::signed_volume(input), 1.0, 0.1);
}

}  // namespace

TEST(SkeletonSimplify, TorusKeepsGenusOneAndReachesTheTarget) {
  const Mesh torus = shapes::torus(2.0f, 0.5f, 64, 24);  // 1536 vertices
  const detail::Simplified s = detail::simplify(torus, 300);
  expect_valid_proxy(torus, s, 300);
  EXPECT_EQ(s.mesh.positions.size(), 300u);
  EXPECT_EQ(s.mesh.triangles.size(), 600u);  // F = 2V on a torus
  EXPECT_EQ(euler_characteristic(s.mesh), 0);
  // Proxy vertices stay near the torus surface (quadrics keep the shape).
  for (const glm::vec3& p : s.mesh.positions) EXPECT_LT(std::abs(shapes::torus_sdf(p, 2.0f, 0.5f)), 0.1f);
}

TEST(SkeletonSimplify, Genus2KeepsTwoHandles) {
  const auto g = models::genus2();
  ASSERT_GT(g.mesh.positions.size(), 600u);
  const detail::Simplified s = detail::simplify(g.mesh, 400);
  expect_valid_proxy(g.mesh, s, 400);
  EXPECT_EQ(euler_characteristic(s.mesh), -2);
  for (const glm::vec3& p : s.mesh.positions) EXPECT_LT(std::abs(g.fn(p)), 0.06f);
}

TEST(SkeletonSimplify, SeveralComponentsStaySeparate) {
  Mesh a = shapes::capsule(0.4f, 2.0f, 24, 24);
  const Mesh b = shapes::icosphere(1.0f, 3);
  const auto offset = static_cast<std::uint32_t>(a.positions.size());
  for (glm::vec3 p : b.positions) a.positions.push_back(p + glm::vec3(4.0f, 0.0f, 0.0f));
  for (Triangle t : b.triangles) a.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  const detail::Simplified s = detail::simplify(a, 250);
  expect_valid_proxy(a, s, 250);
  EXPECT_EQ(euler_characteristic(s.mesh), 4);  // two spheres
  // No proxy vertex takes input vertices of both components.
  std::map<std::uint32_t, bool> side;
  for (std::uint32_t k = 0; k < a.positions.size(); ++k) {
    const auto [it, inserted] = side.try_emplace(s.vertex_map[k], k < offset);
    EXPECT_EQ(it->second, k < offset);
  }
}

TEST(SkeletonSimplify, AnUnreachableTargetStopsAtTheSmallestLegalMesh) {
  // A sphere cannot go below a tetrahedron: asking for 1 vertex leaves a valid closed mesh.
  const Mesh sphere = shapes::icosphere(1.0f, 2);
  const detail::Simplified s = detail::simplify(sphere, 1);
  EXPECT_GE(s.mesh.positions.size(), 4u);
  EXPECT_LT(s.mesh.positions.size(), 20u);
  const MeshReport r = analyze(s.mesh);
  EXPECT_EQ(r.boundary_edges, 0u);
  EXPECT_EQ(r.non_manifold_edges, 0u);
  EXPECT_EQ(r.degenerate_faces, 0u);
  EXPECT_EQ(euler_characteristic(s.mesh), 2);
  EXPECT_GT(test::signed_volume(s.mesh), 0.0);  // still facing outward
}

TEST(SkeletonSimplify, ATargetAboveTheVertexCountChangesNothing) {
  const Mesh torus = shapes::torus(2.0f, 0.5f, 16, 8);
  const detail::Simplified s = detail::simplify(torus, 1000);
  EXPECT_EQ(s.collapses, 0u);
  EXPECT_EQ(s.mesh.positions, torus.positions);
  EXPECT_EQ(s.mesh.triangles, torus.triangles);
  for (std::uint32_t k = 0; k < torus.positions.size(); ++k) EXPECT_EQ(s.vertex_map[k], k);
}

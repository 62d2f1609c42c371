#include "sdfkit/core/error.hpp"
#include "sdfkit/core/mesh.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/core/topology.hpp"
#include "sdfkit/core/weld.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <vector>

using namespace sdfkit;

TEST(Normals, BoxFaceNormalsPointOutward) {
  const Mesh m = shapes::box(2, 2, 2, 3);
  const auto n = face_normals(m);
  const auto c = face_centroids(m);
  for (std::size_t f = 0; f < n.size(); ++f) {
    EXPECT_NEAR(glm::length(n[f]), 1.0f, 1e-5f);
    EXPECT_GT(glm::dot(n[f], c[f]), 0.9f);  // centroid on a face at distance 1 from the origin
  }
}

TEST(Normals, AngleWeightedVertexNormalIgnoresTriangulation) {
  // A cube corner: three faces split into different numbers of triangles. The angle-weighted
  // normal is the diagonal whatever the split.
  const Mesh m = shapes::box(2, 2, 2, 1);
  const auto n = vertex_normals(m);
  for (std::size_t v = 0; v < m.positions.size(); ++v)
    EXPECT_NEAR(glm::dot(n[v], glm::normalize(m.positions[v])), 1.0f, 1e-5f) << v;
}

// vertex_normals keeps its sums in blocks of 2^21 vertices (freed as the output fills): on a
// height field of 1449^2 vertices (two blocks) every normal is the one of a single array of
// sums added in face order (written out here), bit for bit, and close to the surface's analytic
// normal on both sides of the block border.
TEST(Normals, VertexNormalsAcrossSumBlocksAreTheSequentialSums) {
  constexpr std::uint32_t kSide = 1449;  // 2,099,601 vertices > 2^21
  const auto height = [](float x, float y) { return 0.05f * std::sin(x) * std::cos(0.7f * y); };
  Mesh m;
  m.positions.reserve(std::size_t{kSide} * kSide);
  const float step = 0.01f;
  for (std::uint32_t j = 0; j < kSide; ++j)
    for (std::uint32_t i = 0; i < kSide; ++i) {
      const float x = step * static_cast<float>(i), y = step * static_cast<float>(j);
      m.positions.push_back({x, y, height(x, y)});
    }
  for (std::uint32_t j = 0; j + 1 < kSide; ++j)
    for (std::uint32_t i = 0; i + 1 < kSide; ++i) {
      const std::uint32_t a = j * kSide + i, b = a + 1, c = a + kSide, d = c + 1;
      m.triangles.push_back({a, b, d});
      m.triangles.push_back({a, d, c});
    }
  ASSERT_GT(m.positions.size(), std::size_t{1} << 21);
  const std::vector<glm::vec3> n = vertex_normals(m);
  ASSERT_EQ(n.size(), m.positions.size());

  std::vector<glm::dvec3> sum(m.positions.size(), glm::dvec3(0.0));
  for (const Triangle& t : m.triangles) {
    const glm::vec3 a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
    const glm::vec3 fn = glm::normalize(glm::cross(b - a, c - a));
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 p = m.positions[t[k]];
      const glm::vec3 u = m.positions[t[(k + 1) % 3]] - p, v = m.positions[t[(k + 2) % 3]] - p;
      const float angle = std::atan2(glm::length(glm::cross(u, v)), glm::dot(u, v));
      sum[t[k]] += glm::dvec3(fn) * static_cast<double>(angle);
    }
  }
  std::size_t differ = 0;
  for (std::size_t v = 0; v < sum.size(); ++v) differ += n[v] != glm::vec3(sum[v] / glm::length(sum[v]));
  EXPECT_EQ(differ, 0u);
  for (const std::size_t v : {std::size_t{1} << 20, (std::size_t{1} << 21) - 1, std::size_t{1} << 21, sum.size() - kSide - 2}) {
    const float x = m.positions[v].x, y = m.positions[v].y;
    const glm::vec3 analytic = glm::normalize(glm::vec3(-0.05f * std::cos(x) * std::cos(0.7f * y),
                                                        0.035f * std::sin(x) * std::sin(0.7f * y), 1.0f));
    EXPECT_GT(glm::dot(n[v], analytic), 0.99999f) << v;
  }
}

TEST(Normals, DegenerateFacesGiveNoNaN) {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}};
  m.triangles = {{0, 1, 2}, {0, 1, 3}, {3, 3, 3}};
  const auto deg = degenerate_faces(m);
  EXPECT_EQ(deg[0], 1);
  EXPECT_EQ(deg[1], 0);
  EXPECT_EQ(deg[2], 1);
  for (const auto& n : face_normals(m)) EXPECT_TRUE(std::isfinite(n.x + n.y + n.z));
  for (const auto& n : vertex_normals(m)) EXPECT_TRUE(std::isfinite(n.x + n.y + n.z));
  EXPECT_EQ(face_normals(m)[0], glm::vec3(0.0f));
  EXPECT_EQ(face_areas(m)[0], 0.0f);
  EXPECT_NEAR(face_areas(m)[1], 0.5f, 1e-6f);
}

TEST(Validate, RejectsEmptyOutOfRangeAndNonFinite) {
  Mesh empty;
  EXPECT_THROW(validate_mesh(empty, "x"), InputError);
  Mesh bad;
  bad.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  bad.triangles = {{0, 1, 3}};
  EXPECT_THROW(validate_mesh(bad, "x"), InputError);
  bad.triangles = {{0, 1, 2}};
  EXPECT_NO_THROW(validate_mesh(bad, "x"));
  bad.positions[1].y = std::nanf("");
  EXPECT_THROW(validate_mesh(bad, "x"), InputError);
  bad.positions[1].y = INFINITY;
  EXPECT_THROW(validate_mesh(bad, "x"), InputError);
}

TEST(Weld, MergesEqualPositionsAndKeepsTriangleOrder) {
  // Two triangles of a quad, each with its own copies of the shared corners (a glTF seam).
  const glm::vec3 p[] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const Triangle t[] = {{0, 1, 2}, {3, 4, 5}};
  const WeldResult w = weld(p, t);
  EXPECT_EQ(w.mesh.positions.size(), 4u);
  ASSERT_EQ(w.mesh.triangles.size(), 2u);
  EXPECT_EQ(w.input_to_welded[3], w.input_to_welded[0]);
  EXPECT_EQ(w.input_to_welded[4], w.input_to_welded[2]);
  EXPECT_EQ(analyze(w.mesh).boundary_edges, 4u);
}

TEST(Weld, ToleranceMergesNearbyPoints) {
  const glm::vec3 p[] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1e-4f, 0, 0}, {5, 5, 5}};
  const Triangle t[] = {{0, 1, 2}};
  EXPECT_EQ(weld(p, t, 0.0f).mesh.positions.size(), 5u);
  const WeldResult w = weld(p, t, 1e-3f);
  EXPECT_EQ(w.mesh.positions.size(), 4u);
  EXPECT_EQ(w.input_to_welded[3], w.input_to_welded[0]);
}

TEST(Weld, NegativeZeroWeldsWithZero) {
  const glm::vec3 p[] = {{0, 0, 0}, {-0.0f, 0, 0}};
  EXPECT_EQ(weld(p, {}).mesh.positions.size(), 1u);
}

TEST(Topology, ClosedShapesHaveNoBoundary) {
  for (const Mesh& m : {shapes::sphere(1, 16, 8), shapes::torus(2, 0.5f, 24, 12),
                        shapes::box(1, 2, 3, 4), shapes::capped_cylinder(1, 3, 16, 4, 2),
                        shapes::icosphere(1, 2)}) {
    const MeshReport r = analyze(m);
    EXPECT_EQ(r.boundary_edges, 0u);
    EXPECT_EQ(r.non_manifold_edges, 0u);
    EXPECT_EQ(r.components, 1u);
    EXPECT_EQ(r.degenerate_faces, 0u);
  }
}

TEST(Topology, CountsBoundaryNonManifoldComponentsAndIsolated) {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, -1, 0}, {9, 9, 9},
                 {5, 0, 0}, {6, 0, 0}, {5, 1, 0}};
  // Three triangles on edge (0, 1): non-manifold; a separate triangle; vertex 5 unused.
  m.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {6, 7, 8}};
  const MeshReport r = analyze(m);
  EXPECT_EQ(r.non_manifold_edges, 1u);
  EXPECT_EQ(r.components, 2u);
  EXPECT_EQ(r.isolated_vertices, 1u);
  EXPECT_EQ(r.boundary_edges, 6u + 3u);
}

TEST(Topology, AdjacencyOfATetrahedron) {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  const Adjacency v = vertex_adjacency(m);
  const Adjacency f = face_adjacency(m);
  for (std::uint32_t i = 0; i < 4; ++i) {
    EXPECT_EQ(v.offsets[i + 1] - v.offsets[i], 3u);
    EXPECT_EQ(f.offsets[i + 1] - f.offsets[i], 3u);
  }
}

// The edge grouping behind analyze() and face_adjacency() (a counting sort by the smaller end,
// or a comparison sort when an index is past the vertices) against a map of every edge's faces,
// on a random soup over few vertices: repeated indices, edges of one to many faces.
TEST(Topology, EdgeCountsAndFaceAdjacencyEqualAMapOfEdges) {
  for (const bool index_past_the_vertices : {false, true}) {
    Mesh m;
    for (int i = 0; i < 40; ++i) m.positions.push_back({std::cos(1.3f * i), std::sin(0.7f * i), 0.05f * i});
    std::uint32_t seed = 12345;
    const auto next = [&] { return (seed = seed * 1664525u + 1013904223u) >> 8; };
    for (int f = 0; f < 400; ++f) m.triangles.push_back({next() % 40, next() % 40, next() % 40});
    if (index_past_the_vertices) m.triangles.push_back({0, 1, 1000});
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> faces_of;
    for (std::uint32_t f = 0; f < m.triangles.size(); ++f)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = m.triangles[f][k], b = m.triangles[f][(k + 1) % 3];
        if (a != b) faces_of[{std::min(a, b), std::max(a, b)}].push_back(f);
      }
    std::size_t boundary = 0, non_manifold = 0;
    std::set<std::pair<std::uint32_t, std::uint32_t>> neighbours;
    for (const auto& [edge, faces] : faces_of) {
      boundary += faces.size() == 1;
      non_manifold += faces.size() >= 3;
      for (std::uint32_t f : faces)
        for (std::uint32_t g : faces)
          if (f != g) neighbours.insert({f, g});
    }
    const MeshReport r = analyze(m);
    EXPECT_EQ(r.boundary_edges, boundary);
    EXPECT_EQ(r.non_manifold_edges, non_manifold);
    EXPECT_GT(non_manifold, 0u);
    const Adjacency adj = face_adjacency(m);
    std::set<std::pair<std::uint32_t, std::uint32_t>> got;
    for (std::uint32_t f = 0; f < adj.size(); ++f)
      for (std::uint32_t i = adj.offsets[f]; i < adj.offsets[f + 1]; ++i) got.insert({f, adj.indices[i]});
    EXPECT_EQ(got, neighbours);
  }
}

TEST(Topology, RingsOfFlaggedVerticesOnlyEqualTheWholeAdjacencys) {
  const Mesh m = shapes::icosphere(1, 3);
  const Adjacency all = vertex_adjacency(m);
  std::vector<std::uint8_t> flags(m.positions.size());
  for (std::size_t v = 0; v < flags.size(); ++v) flags[v] = v % 3 == 1;
  const Adjacency some = vertex_adjacency(m, flags);
  ASSERT_EQ(some.size(), all.size());
  for (std::size_t v = 0; v < flags.size(); ++v) {
    const std::vector<std::uint32_t> a(all.indices.begin() + all.offsets[v], all.indices.begin() + all.offsets[v + 1]);
    const std::vector<std::uint32_t> b(some.indices.begin() + some.offsets[v], some.indices.begin() + some.offsets[v + 1]);
    if (flags[v]) {
      EXPECT_EQ(b, a) << v;
      EXPECT_GE(b.size(), 5u) << v;
    } else {
      EXPECT_TRUE(b.empty()) << v;
    }
  }
  EXPECT_LT(some.indices.size(), all.indices.size() / 2);
}

TEST(Subdivide, QuadruplesFacesKeepsTheSurfaceAndStaysClosed) {
  const Mesh m = shapes::icosphere(1, 2);
  const Mesh s = subdivide_midpoint(m);
  EXPECT_EQ(s.triangles.size(), 4 * m.triangles.size());
  const MeshReport r = analyze(m), rs = analyze(s);
  // V' = V + E, and E = 3F/2 on a closed triangle mesh.
  EXPECT_EQ(s.positions.size(), m.positions.size() + 3 * m.triangles.size() / 2);
  EXPECT_EQ(rs.boundary_edges, 0u);
  EXPECT_EQ(rs.components, r.components);
  double area = 0, area_s = 0;
  for (float a : face_areas(m)) area += a;
  for (float a : face_areas(s)) area_s += a;
  EXPECT_NEAR(area_s, area, 1e-4 * area);
}

// Skeletons of real meshes from CGAL's data set (Embree reference as the SDF backend), held to
// properties that a skeleton must have whatever the pipeline does inside: one connected part
// per component, independent cycles = the solid's genus, every node and every point of every
// curve edge inside the solid (generalized winding number by solid angles, independent of the
// library's ray-crossing test), a leaf near the tip of each limb, few sheet nodes on tubular shapes, and the
// same output byte for byte across runs. sdfkit_skeleton_bench --eval measures the same
// quantities over the whole data set (engine/skeleton/README.md).

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/mesh.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/core/weld.hpp"
#include "sdfkit/core/topology.hpp"
#include "sdfkit/core/union_find.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/reference/embree_backend.hpp"
#include "sdfkit/skeleton/skeleton.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "analytic.hpp"
#include "bvh.hpp"       // engine/skeleton (private): the segment test the library and the eval use
#include "validate.hpp"  // engine/skeleton (private): split_non_manifold

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <string>

using namespace sdfkit;
namespace sk = sdfkit::skeleton;

namespace {

sk::Skeleton extract(const Mesh& mesh) {
  reference::EmbreeBackend backend;
  return sk::extract(mesh, &backend, {}, {});
}

Mesh load(const char* name) { return io::load_asset(test::data_mesh(name)).mesh; }

// Generalized winding number (solid angles): 1 inside a closed mesh, 0 outside.
double winding_number(const Mesh& m, const glm::vec3& p) {
  double total = 0.0;
  for (const Triangle& t : m.triangles) {
    const glm::dvec3 a = glm::dvec3(m.positions[t[0]]) - glm::dvec3(p);
    const glm::dvec3 b = glm::dvec3(m.positions[t[1]]) - glm::dvec3(p);
    const glm::dvec3 c = glm::dvec3(m.positions[t[2]]) - glm::dvec3(p);
    const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
    const double num = glm::dot(a, glm::cross(b, c));
    const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(b, c) * la + glm::dot(c, a) * lb;
    total += 2.0 * std::atan2(num, den);
  }
  return total / (4.0 * M_PI);
}

// Genus of a closed mesh: sum over its components of (2 - chi) / 2.
int genus(const Mesh& mesh) {
  UnionFind uf(mesh.positions.size());
  for (const Triangle& t : mesh.triangles) uf.unite(t[0], t[1]), uf.unite(t[1], t[2]);
  std::map<std::uint32_t, long> chi;
  std::set<std::uint32_t> used;
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (const Triangle& t : mesh.triangles) {
    chi[uf.find(t[0])] += 1;
    for (int i = 0; i < 3; ++i) {
      if (used.insert(t[i]).second) chi[uf.find(t[i])] += 1;
      if (edges.insert({std::min(t[i], t[(i + 1) % 3]), std::max(t[i], t[(i + 1) % 3])}).second)
        chi[uf.find(t[i])] -= 1;
    }
  }
  long g = 0;
  for (const auto& [root, x] : chi) g += (2 - x) / 2;
  return static_cast<int>(g);
}

std::vector<int> degrees(const sk::Skeleton& s) {
  std::set<std::array<std::uint32_t, 2>> all(s.edges.begin(), s.edges.end());
  for (const Triangle& t : s.sheet_triangles)
    for (int i = 0; i < 3; ++i) all.insert({std::min(t[i], t[(i + 1) % 3]), std::max(t[i], t[(i + 1) % 3])});
  std::vector<int> d(s.nodes.size(), 0);
  for (const auto& e : all) ++d[e[0]], ++d[e[1]];
  return d;
}

int parts(const sk::Skeleton& s) {
  UnionFind uf(s.nodes.size());
  int count = static_cast<int>(s.nodes.size());
  for (const auto& e : s.edges) count -= uf.unite(e[0], e[1]);
  for (const Triangle& t : s.sheet_triangles) count -= uf.unite(t[0], t[1]), count -= uf.unite(t[1], t[2]);
  return count;
}

double sheet_share(const sk::Skeleton& s) {
  std::size_t sheet = 0;
  for (const sk::Node& n : s.nodes) sheet += n.sheet;
  return static_cast<double>(sheet) / static_cast<double>(s.nodes.size());
}

// The checks every skeleton of a closed mesh must pass.
void expect_valid(const Mesh& mesh, const sk::Skeleton& s, const char* name) {
  ASSERT_FALSE(s.nodes.empty()) << name;
  std::vector<int> count(mesh.positions.size(), 0);
  for (const sk::Node& n : s.nodes) {
    for (std::uint32_t v : n.vertices) ++count[v];
    ASSERT_TRUE(std::isfinite(n.position.x) && std::isfinite(n.position.y) && std::isfinite(n.position.z)) << name;
    EXPECT_TRUE(std::isfinite(n.radius) && n.radius > 0.0f) << name;
    EXPECT_GT(winding_number(mesh, n.position), 0.5) << name << ": node outside the solid";
  }
  for (std::size_t v = 0; v < count.size(); ++v) ASSERT_EQ(count[v], 1) << name << ": vertex " << v;
  // Curve edges inside (7 points per edge between its ends). Not yet every one: where no
  // detour through the solid is found, a bridge that leaves it is kept rather than cutting the
  // skeleton (camel.off 1 of 40; man.off and cow.off had 2 before the re-routing along centre
  // points, 29 of 152 and 9 of 54 before the detours).
  std::size_t outside = 0;
  for (const auto& e : s.edges)
    for (int i = 1; i < 8; ++i) {
      const glm::vec3 p = glm::mix(s.nodes[e[0]].position, s.nodes[e[1]].position, static_cast<float>(i) / 8.0f);
      if (winding_number(mesh, p) < 0.5) {
        ++outside;
        break;
      }
    }
  EXPECT_LE(outside, 1u) << name << ": curve edges leave the solid";
  EXPECT_EQ(sk::cycle_count(s), genus(mesh)) << name;
  EXPECT_EQ(static_cast<std::size_t>(parts(s)), analyze(mesh).components) << name;
}

// Distance from p to the nearest leaf (node of degree 1), as a share of the bbox diagonal.
double nearest_leaf(const Mesh& mesh, const sk::Skeleton& s, const glm::vec3& p) {
  const auto d = degrees(s);
  double best = 1e30;
  for (std::size_t i = 0; i < s.nodes.size(); ++i)
    if (d[i] == 1) best = std::min<double>(best, glm::length(s.nodes[i].position - p));
  return best / bounding_box(mesh.positions).diagonal();
}

// The vertex extreme along `dir`.
glm::vec3 extreme(const Mesh& mesh, const glm::vec3& dir) {
  glm::vec3 best = mesh.positions.front();
  for (const glm::vec3& p : mesh.positions)
    if (glm::dot(p, dir) > glm::dot(best, dir)) best = p;
  return best;
}

}  // namespace

// A standing human (z up, arms down): a tree inside the body, sheets the exception, a leaf at
// the head and at the lowest foot. Before the region nodes: 99 % sheet nodes, 54 cycles.
TEST(SkeletonRealMeshes, HumanIsATreeInsideWithLeavesAtHeadAndFoot) {
  const Mesh mesh = load("man.off");
  const sk::Skeleton s = extract(mesh);
  expect_valid(mesh, s, "man.off");
  EXPECT_LE(sheet_share(s), 0.10);
  EXPECT_GE(s.curve_reliability, 0.85);
  EXPECT_LT(nearest_leaf(mesh, s, extreme(mesh, {0, 0, 1})), 0.10) << "head";
  EXPECT_LT(nearest_leaf(mesh, s, extreme(mesh, {0, 0, -1})), 0.10) << "foot";
}

// A quadruped (CGAL's camel): legs, head and tail get leaves; no sheet at all is needed.
TEST(SkeletonRealMeshes, CamelHasLeavesAtItsExtremities) {
  const Mesh mesh = load("camel.off");
  const sk::Skeleton s = extract(mesh);
  expect_valid(mesh, s, "camel.off");
  EXPECT_LE(sheet_share(s), 0.10);
  EXPECT_GE(s.curve_reliability, 0.95);
  const auto d = degrees(s);
  EXPECT_GE(std::count(d.begin(), d.end(), 1), 6);  // four legs, head, tail
  // The file is y up, head and tail along z.
  EXPECT_LT(nearest_leaf(mesh, s, extreme(mesh, {0, -1, 0})), 0.10) << "the lowest hoof";
  EXPECT_LT(nearest_leaf(mesh, s, extreme(mesh, {0, 0, 1})), 0.10) << "+z end";
  EXPECT_LT(nearest_leaf(mesh, s, extreme(mesh, {0, 0, -1})), 0.10) << "-z end";
}

// CGAL's homer (y up, feet at the bottom, legs straight): the surgery joins the pelvis straight
// to a foot and leaves the knee's node hanging off the foot, so the branch ended at the knee,
// 0.157 of the diagonal from the foot's lowest vertex, on both legs. A leaf that lies inside the
// tube of the edge its neighbour continues on is threaded into that edge, and the branch ends at
// the foot. The knee of a bent leg lies off the hip-foot chord by more than the tube between the
// thick hip and the thin foot allows; it is threaded when the chord passes through its own ball
// (RESULTS, "A knee threaded by its own ball"): both legs, where s11leaves held on one.
TEST(SkeletonRealMeshes, StraightLegEndsAtTheFootNotTheKnee) {
  const Mesh mesh = load("homer.off");
  const sk::Skeleton s = extract(mesh);
  expect_valid(mesh, s, "homer.off");
  const float cx = bounding_box(mesh.positions).center().x;
  for (const bool left : {true, false}) {
    glm::vec3 foot{0.0f, 1e30f, 0.0f};
    for (const glm::vec3& p : mesh.positions)
      if ((p.x < cx) == left && p.y < foot.y) foot = p;
    EXPECT_LT(nearest_leaf(mesh, s, foot), 0.12) << (left ? "left" : "right") << " leg's branch does not reach its foot";
  }
}

// Parts that the contraction merged whole into a node of the body (s11branch): bunny00's ear
// and elk's hind foot contracted into the body's nodes and their vertices see those nodes, so
// no unseen region gave them a branch: without SkeletonOptions::protrusion_branches the nearest
// leaf is 0.136 of the diagonal from the ear's tip (the vertex extreme along (-1, 0, -1)) and
// 0.274 from elk's lowest vertex (Embree; CGAL's skeleton has a leaf at each). A region of
// vertices whose centre points lie outside the skeleton's balls, reaching farther from its base
// than the base's radius, gets a branch with a leaf at its tip: 0.047 and 0.055 when this test
// was written, inside the solid, cycles unchanged. Later steps moved the ear's leaf: 0.073
// before the twentieth session, 0.079 with the branches threaded into the limbs they lie
// beside (the ear's branch wanders: its node nearest the tip, 0.036 away, is not its leaf);
// the elk's 0.059. The bound is the test's since it was written.
TEST(SkeletonRealMeshes, ProtrusionMergedIntoTheBodyGetsABranch) {
  {
    const Mesh mesh = load("bunny00.off");
    const sk::Skeleton s = extract(mesh);
    expect_valid(mesh, s, "bunny00.off");
    std::printf("bunny00: ear tip to the nearest leaf %.4f of the diagonal\n", nearest_leaf(mesh, s, extreme(mesh, {-1, 0, -1})));
    EXPECT_LT(nearest_leaf(mesh, s, extreme(mesh, {-1, 0, -1})), 0.08) << "bunny00's ear";
  }
  {
    const Mesh mesh = load("elk.off");
    const sk::Skeleton s = extract(mesh);
    expect_valid(mesh, s, "elk.off");
    std::printf("elk: hind foot to the nearest leaf %.4f of the diagonal\n", nearest_leaf(mesh, s, extreme(mesh, {0, 0, -1})));
    EXPECT_LT(nearest_leaf(mesh, s, extreme(mesh, {0, 0, -1})), 0.08) << "elk's hind foot";
  }
}

// Distance from p to triangle abc (closest point by the triangle's Voronoi regions).
double distance_to_triangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return glm::length(p - a);
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return glm::length(p - b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return glm::length(p - c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  const double denom = 1.0 / (va + vb + vc);
  return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

double distance_to_surface(const Mesh& m, const glm::vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const Triangle& t : m.triangles)
    best = std::min(best, distance_to_triangle(glm::dvec3(p), glm::dvec3(m.positions[t[0]]), glm::dvec3(m.positions[t[1]]),
                                               glm::dvec3(m.positions[t[2]])));
  return best;
}

// A leaf is a node like any other: it sits at the centre of the part of the solid its vertices
// enclose, about its radius (SDF/2) inside the surface, not on it. The tip node of a limb once
// sat at the centre point of the limb's extreme vertex, within that vertex's SDF/2 of the
// surface at a tapering tip: 0.13 radii from the surface for bunny00's ear leaf (803 vertices),
// 0.15 for a diplodocus foot (301), 0.35 for the hand's thumb (81); at the centre of its
// vertices 0.46-0.78. Leaves carrying at least 1 % of the vertices (a limb's end, not a stub
// node left by the cross-sections) must lie 0.4 radii inside: a tolerance under the ideal 1.
TEST(SkeletonRealMeshes, LeavesSitAtTheCentreOfTheirRegion) {
  for (const char* name : {"diplodocus.off", "hand.off", "bunny00.off"}) {
    const Mesh mesh = load(name);
    const sk::Skeleton s = extract(mesh);
    expect_valid(mesh, s, name);
    std::vector<int> degree(s.nodes.size(), 0);
    for (const auto& e : s.edges) ++degree[e[0]], ++degree[e[1]];
    int checked = 0;
    for (std::size_t l = 0; l < s.nodes.size(); ++l) {
      const sk::Node& node = s.nodes[l];
      if (degree[l] != 1 || node.sheet || 100 * node.vertices.size() < mesh.positions.size()) continue;
      ++checked;
      const double inside = distance_to_surface(mesh, node.position) / static_cast<double>(node.radius);
      EXPECT_GE(inside, 0.4) << name << ": leaf " << l << " (" << node.vertices.size() << " vertices) lies " << inside
                             << " of its radius inside the surface";
    }
    EXPECT_GT(checked, 0) << name;
  }
}

TEST(SkeletonRealMeshes, CowIsATreeInsideTheSolid) {
  const Mesh mesh = load("cow.off");
  const sk::Skeleton s = extract(mesh);
  expect_valid(mesh, s, "cow.off");
  EXPECT_LE(sheet_share(s), 0.10);
}

// A genus-2 tube knot: two cycles, all curve.
TEST(SkeletonRealMeshes, Genus2KnotHasTwoCycles) {
  const Mesh mesh = load("knot2.off");
  ASSERT_EQ(genus(mesh), 2);
  const sk::Skeleton s = extract(mesh);
  expect_valid(mesh, s, "knot2.off");
  EXPECT_LE(sheet_share(s), 0.10);
}

// CGAL's P (26 vertices, genus 1): the contracted ring of the P's bowl is three nodes; an
// edge of that triangle leaves the solid, and its detour must not go along the other two edges
// (that dropped the cycle: 0 cycles before).
TEST(SkeletonRealMeshes, CoarseHandleKeepsItsCycle) {
  const Mesh mesh = load("P.off");
  ASSERT_EQ(genus(mesh), 1);
  const sk::Skeleton s = extract(mesh);
  expect_valid(mesh, s, "P.off");
}

// CGAL's elephant (genus 3: trunk and tail loops, ears): three cycles, every node and curve
// edge inside, the ears curves rather than sheet blobs. Before the slower contraction for
// meshes with handles (ContractionOptions::sl_handles): 6 cycles and 75 % sheet nodes.
TEST(SkeletonRealMeshes, ElephantKeepsItsThreeHandles) {
  const Mesh mesh = load("elephant.off");
  ASSERT_EQ(genus(mesh), 3);
  const sk::Skeleton s = extract(mesh);
  expect_valid(mesh, s, "elephant.off");
  EXPECT_LE(sheet_share(s), 0.10);
}

// Thin handles that the contraction shrinks to a few nodes (CGAL's eight: a plate with two
// holes, genus 2; joint, genus 2; helmet, genus 3): the plain surgery closed them (0, 1 and 0
// cycles), the surgery's handle guard keeps every loop round a hole of the solid.
TEST(SkeletonRealMeshes, ThinHandlesKeepTheirCycles) {
  for (const char* name : {"eight.off", "joint.off", "helmet.off"}) {
    const Mesh mesh = load(name);
    ASSERT_GT(genus(mesh), 1) << name;
    const sk::Skeleton s = extract(mesh);
    expect_valid(mesh, s, name);
    EXPECT_EQ(sk::to_json(s), sk::to_json(extract(mesh))) << name << ": not deterministic";
  }
}

// CGAL's diplodocus has two non-manifold edges: the skeleton is built (on the mesh split there)
// instead of refused; every input vertex is still in exactly one node.
TEST(SkeletonRealMeshes, NonManifoldEdgesAreSplitNotRefused) {
  const Mesh mesh = load("diplodocus.off");
  ASSERT_GT(analyze(mesh).non_manifold_edges, 0u);
  const sk::Skeleton s = extract(mesh);
  ASSERT_FALSE(s.warnings.empty());
  EXPECT_NE(s.warnings.front().find("non-manifold"), std::string::npos) << s.warnings.front();
  ASSERT_FALSE(s.nodes.empty());
  std::vector<int> count(mesh.positions.size(), 0);
  for (const sk::Node& n : s.nodes) {
    for (std::uint32_t v : n.vertices) ++count[v];
    EXPECT_TRUE(std::isfinite(n.position.x) && std::isfinite(n.radius));
  }
  for (int c : count) ASSERT_EQ(c, 1);
  EXPECT_EQ(s.sdf.size(), mesh.positions.size());
  EXPECT_EQ(sk::cycle_count(s), 0);
}

// Same input, same options: the same JSON, byte for byte.
TEST(SkeletonRealMeshes, OutputIsDeterministic) {
  const Mesh mesh = load("cow.off");
  const std::string a = sk::to_json(extract(mesh)), b = sk::to_json(extract(mesh));
  EXPECT_EQ(a, b);
}

// An open mesh is still refused with one clear line.
TEST(SkeletonRealMeshes, OpenMeshIsRefusedWithAClearError) {
  const Mesh mesh = load("cube-ouvert.off");
  try {
    extract(mesh);
    FAIL() << "an open mesh was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("boundary edges"), std::string::npos) << e.what();
  }
}

// Two boxes touching along one edge (the four triangles there share it): the split gives two
// closed edge-manifold boxes again, with the edge's two vertices duplicated, and the skeleton
// has one part per box.
TEST(SkeletonRealMeshes, BoxesTouchingAlongAnEdgeAreSplitIntoTwoSolids) {
  const Mesh a = shapes::box(1.0f, 1.0f, 1.0f, 2);
  Mesh m = a;
  // The second box: shifted by (1, 1, 0) (centred boxes of size 1 meet along x = y = 0.5).
  const std::uint32_t offset = static_cast<std::uint32_t>(m.positions.size());
  for (const glm::vec3& p : a.positions) m.positions.push_back(p + glm::vec3(1.0f, 1.0f, 0.0f));
  for (const Triangle& t : a.triangles) m.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  m = weld(m.positions, m.triangles, 1e-6f).mesh;
  const MeshReport before = analyze(m);
  ASSERT_GT(before.non_manifold_edges, 0u);
  ASSERT_EQ(before.boundary_edges, 0u);
  ASSERT_EQ(before.components, 1u);
  const sk::detail::ManifoldSplit split = sk::detail::split_non_manifold(m, "test");
  ASSERT_TRUE(split.applied);
  const MeshReport after = analyze(split.mesh);
  EXPECT_EQ(after.non_manifold_edges, 0u);
  EXPECT_EQ(after.boundary_edges, 0u);
  EXPECT_EQ(after.components, 2u);
  EXPECT_EQ(split.mesh.positions.size(), m.positions.size() + 3);  // the edge's 3 vertices (n = 2)
  for (std::size_t v = 0; v < split.mesh.positions.size(); ++v)
    EXPECT_EQ(split.mesh.positions[v], m.positions[split.original[v]]);
  const sk::Skeleton s = extract(m);
  EXPECT_EQ(parts(s), 2);
  std::vector<int> count(m.positions.size(), 0);
  for (const sk::Node& n : s.nodes)
    for (std::uint32_t v : n.vertices) ++count[v];
  for (int c : count) EXPECT_EQ(c, 1);
}

namespace {
// Each terminal curve branch (a leaf and its chain of degree-2 curve nodes up to a node of
// degree >= 3): its nodes, then the junction.
std::vector<std::vector<std::uint32_t>> terminal_branches(const sk::Skeleton& s) {
  std::vector<std::vector<std::uint32_t>> adj(s.nodes.size());
  std::set<std::array<std::uint32_t, 2>> all(s.edges.begin(), s.edges.end());
  for (const Triangle& t : s.sheet_triangles)
    for (int i = 0; i < 3; ++i) all.insert({std::min(t[i], t[(i + 1) % 3]), std::max(t[i], t[(i + 1) % 3])});
  for (const auto& e : all) adj[e[0]].push_back(e[1]), adj[e[1]].push_back(e[0]);
  std::vector<std::vector<std::uint32_t>> out;
  for (std::uint32_t leaf = 0; leaf < s.nodes.size(); ++leaf) {
    if (adj[leaf].size() != 1 || s.nodes[leaf].sheet) continue;
    std::vector<std::uint32_t> path{leaf};
    std::uint32_t prev = leaf, cur = adj[leaf].front();
    while (adj[cur].size() == 2 && !s.nodes[cur].sheet) {
      path.push_back(cur);
      const std::uint32_t next = adj[cur][0] == prev ? adj[cur][1] : adj[cur][0];
      prev = cur, cur = next;
    }
    if (adj[cur].size() < 3 || s.nodes[cur].sheet) continue;
    path.push_back(cur);
    out.push_back(std::move(path));
  }
  return out;
}

// Whether q lies in what the skeleton stands for outside the nodes `own`: the other curve nodes'
// balls swept along the curve edges between them (radius interpolated along each edge).
bool in_rest(const sk::Skeleton& s, const std::set<std::uint32_t>& own, const glm::vec3& q) {
  const auto rest = [&](std::uint32_t m) { return !own.count(m) && !s.nodes[m].sheet; };
  for (std::uint32_t m = 0; m < s.nodes.size(); ++m)
    if (rest(m) && glm::length(q - s.nodes[m].position) <= s.nodes[m].radius) return true;
  for (const auto& e : s.edges) {
    if (!rest(e[0]) || !rest(e[1])) continue;
    const sk::Node& e0 = s.nodes[e[0]];
    const sk::Node& e1 = s.nodes[e[1]];
    const glm::vec3 ab = e1.position - e0.position;
    const float len2 = glm::dot(ab, ab);
    const float t = len2 > 0.0f ? std::clamp(glm::dot(q - e0.position, ab) / len2, 0.0f, 1.0f) : 0.0f;
    if (glm::length(q - (e0.position + t * ab)) <= e0.radius + t * (e1.radius - e0.radius)) return true;
  }
  return false;
}

// Terminal curve branches whose every ball lies in what the rest of the skeleton stands for:
// the other curve nodes' balls swept along the curve edges between them (radius interpolated
// along each edge), tested at each ball's centre and 26 + 64 points on its sphere (the 3x3x3
// grid's directions, which the library samples, and 64 spherical Fibonacci directions more): a
// branch this finds covered is covered at the library's samples too.
std::size_t covered_branches(const sk::Skeleton& s) {
  std::vector<glm::vec3> directions{glm::vec3(0.0f)};
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz)
        if (dx || dy || dz) directions.push_back(glm::normalize(glm::vec3(dx, dy, dz)));
  for (int i = 0; i < 64; ++i) {
    const float z = 1.0f - (2.0f * static_cast<float>(i) + 1.0f) / 64.0f, r = std::sqrt(1.0f - z * z);
    const float phi = static_cast<float>(i) * 2.39996323f;
    directions.push_back({r * std::cos(phi), r * std::sin(phi), z});
  }
  std::size_t covered = 0;
  for (const auto& branch : terminal_branches(s)) {
    const std::set<std::uint32_t> own(branch.begin(), branch.end() - 1);
    bool all_in = true;
    for (std::size_t i = 0; i + 1 < branch.size() && all_in; ++i) {
      const sk::Node& a = s.nodes[branch[i]];
      for (const glm::vec3& d : directions) {
        if (!in_rest(s, own, a.position + a.radius * d)) {
          all_in = false;
          break;
        }
      }
    }
    covered += all_in;
  }
  return covered;
}

// The largest excess |node - junction| + r_node - r_junction over the nodes of each terminal
// curve branch (a leaf and its chain of degree-2 curve nodes up to a node of degree >= 3);
// one value per branch. A negative value: every ball of the branch lies in the junction's.
std::vector<float> branch_excess(const sk::Skeleton& s) {
  std::vector<float> out;
  for (const auto& branch : terminal_branches(s)) {
    const sk::Node& j = s.nodes[branch.back()];
    float excess = -1e30f;
    for (std::size_t i = 0; i + 1 < branch.size(); ++i)
      excess = std::max(excess, glm::length(s.nodes[branch[i]].position - j.position) + s.nodes[branch[i]].radius - j.radius);
    out.push_back(excess);
  }
  return out;
}
}  // namespace

// A terminal branch whose balls all lie inside its junction's ball is a bump, not a limb
// (SkeletonOptions::prune_branches). CGAL's man: without the pruning such branches exist (64 -> 53
// leaves in the OpenCL eval); with it none is left, fewer leaves, and the skeleton keeps every
// property of expect_valid (tree, inside, every vertex in one node).
TEST(SkeletonRealMeshes, BranchesInsideTheirJunctionBallArePruned) {
  const Mesh mesh = load("man.off");
  reference::EmbreeBackend backend;
  sk::SkeletonOptions off;
  off.prune_branches = false;
  const sk::Skeleton before = sk::extract(mesh, &backend, {}, off);
  const sk::Skeleton after = sk::extract(mesh, &backend, {}, {});
  const auto excess_before = branch_excess(before);
  EXPECT_GT(std::count_if(excess_before.begin(), excess_before.end(), [](float x) { return x < 0.0f; }), 0);
  // The leaf-tip extension runs after the pruning and moves a leaf out by up to its limb's
  // tip, so "none left" is checked without it.
  sk::SkeletonOptions no_tips;
  no_tips.extend_leaves = false;
  const auto excess_after = branch_excess(sk::extract(mesh, &backend, {}, no_tips));
  EXPECT_EQ(std::count_if(excess_after.begin(), excess_after.end(), [](float x) { return x < 0.0f; }), 0);
  const auto leaves = [](const sk::Skeleton& s) {
    const auto d = degrees(s);
    return std::count(d.begin(), d.end(), 1);
  };
  EXPECT_LT(leaves(after), leaves(before));
  expect_valid(mesh, after, "man.off");
}

// A spur beside a limb's own curve, whose balls the limb's nodes and the limb's curve between
// them cover together though no single ball does (the armadillo's forearm and legs), describes
// nothing the rest of the skeleton does not and is pruned like a bump inside its junction's
// ball. Without the pruning the armadillo has such branches; with it none is left (checked at a
// superset of the library's sample points), and there are fewer leaves. (With the nodes' balls
// alone and not the edges swept between them, two such spurs stayed: a ball centred on a limb's
// curve between two of its nodes is not inside either node's ball.)
TEST(SkeletonRealMeshes, SpursCoveredByTheRestOfTheSkeletonArePruned) {
  const Mesh mesh = load("armadillo.off");
  reference::EmbreeBackend backend;
  sk::SkeletonOptions off;
  off.prune_branches = false;
  off.extend_leaves = false;
  const sk::Skeleton before = sk::extract(mesh, &backend, {}, off);
  sk::SkeletonOptions no_tips;  // the tip nodes are added after the pruning
  no_tips.extend_leaves = false;
  const sk::Skeleton after = sk::extract(mesh, &backend, {}, no_tips);
  EXPECT_GT(covered_branches(before), 0u);
  EXPECT_EQ(covered_branches(after), 0u);
  const auto leaves = [](const sk::Skeleton& s) {
    const auto d = degrees(s);
    return std::count(d.begin(), d.end(), 1);
  };
  std::printf("armadillo: leaves without pruning %td, with %td\n", leaves(before), leaves(after));
  EXPECT_LT(leaves(after), leaves(before));
  expect_valid(mesh, after, "armadillo.off");
}

namespace {
// Terminal curve branches whose nodes' centres all lie in what the rest of the skeleton stands
// for (the other curve nodes' balls swept along the curve edges between them): the branch's
// curve never leaves the rest, so its leaf marks no extremity of the solid (a spur).
std::size_t spur_branches(const sk::Skeleton& s) {
  std::size_t spurs = 0;
  for (const auto& branch : terminal_branches(s)) {
    const std::set<std::uint32_t> own(branch.begin(), branch.end() - 1);
    bool all_in = true;
    for (std::size_t i = 0; i + 1 < branch.size() && all_in; ++i) all_in = in_rest(s, own, s.nodes[branch[i]].position);
    spurs += all_in;
  }
  return spurs;
}
}  // namespace

// Vertices in a crease of a limb may see none of the limb's nodes; the node that their region
// gets lies inside the limb's tube, and hung off the nearest node it sees it was a spur: on the
// armadillo and the man most leaves were spurs whose curve never leaves the rest of the
// skeleton (with Embree, as here: 52 of 72 and 27 of 49). Such a node now goes on the curve
// edge whose swept ball holds it (20 of 43 and 7 of 30; with the strands threaded into their
// limbs, 9 of 32 and 2 of 25). Most leaves must reach out of the rest of the skeleton.
TEST(SkeletonRealMeshes, MostLeavesReachOutOfTheRestOfTheSkeleton) {
  for (const char* name : {"armadillo.off", "man.off"}) {
    const sk::Skeleton s = extract(load(name));
    const auto d = degrees(s);
    const auto leaves = static_cast<std::size_t>(std::count(d.begin(), d.end(), 1));
    const std::size_t spurs = spur_branches(s);
    std::printf("%s: %zu leaves, %zu of them on spurs inside the rest of the skeleton\n", name, leaves, spurs);
    EXPECT_LT(2 * spurs, leaves) << name;
  }
}

namespace {
// Terminal branches that run out and come back: a node of the branch lies farther from the
// branch's junction than its leaf, by more than the two nodes' radii.
std::size_t folded_branches(const sk::Skeleton& s) {
  std::size_t folded = 0;
  for (const auto& branch : terminal_branches(s)) {
    const glm::vec3 junction = s.nodes[branch.back()].position;
    const sk::Node& leaf = s.nodes[branch.front()];
    for (std::size_t i = 1; i + 1 < branch.size(); ++i) {
      const sk::Node& n = s.nodes[branch[i]];
      if (glm::length(n.position - junction) - glm::length(leaf.position - junction) > n.radius + leaf.radius) {
        ++folded;
        break;
      }
    }
  }
  return folded;
}
}  // namespace

// A leg that contracted to a flat ribbon collapses to its two rims, joined at the hoof; the
// chain ran down to the hoof and back up, its leaf at mid-leg (CGAL's cow and bull in the eval,
// 2 + 1 of CGAL's leaves missed). With SkeletonOptions::unfold_branches the returning run is
// threaded into the limb it lies beside and the leaf is where the branch turned. Held on the
// cow (both front legs) and the man (a foot) with Embree's SDF, whose skeletons fold without it
// (checked), with the cycles unchanged and every property of expect_valid. (The criterion here,
// a node farther from the junction than the leaf by more than the two radii, is wider than the
// rule's: the armadillo keeps one such branch, whose return lies in a thicker part of the body,
// not beside the way out.)
TEST(SkeletonRealMeshes, TerminalBranchesEndWhereTheyTurn) {
  reference::EmbreeBackend backend;
  sk::SkeletonOptions off;
  off.unfold_branches = false;
  std::size_t folded_before = 0;
  for (const char* name : {"cow.off", "man.off"}) {
    const Mesh mesh = load(name);
    const sk::Skeleton before = sk::extract(mesh, &backend, {}, off);
    const sk::Skeleton after = sk::extract(mesh, &backend, {}, {});
    std::printf("%s: folded branches without unfolding %zu, with %zu\n", name, folded_branches(before),
                folded_branches(after));
    folded_before += folded_branches(before);
    EXPECT_EQ(folded_branches(after), 0u) << name;
    EXPECT_EQ(sk::cycle_count(after), sk::cycle_count(before)) << name;
    expect_valid(mesh, after, name);
  }
  EXPECT_GT(folded_before, 0u);
}

// A rim of a limb that contracted flat can hang from the junction as a strand of its own beside
// the limb's chain, its leaf in the middle of the limb (the armadillo's legs). Its nodes lie
// beside the limb's edges, so SkeletonOptions::unfold_branches threads them into the limb: with
// Embree, the leaves whose branch never leaves the rest of the skeleton (spur_branches) fall
// from 20 of 43 to 9 of 32 on the armadillo and from 7 of 30 to 2 of 25 on the man; the cycles
// stay and every property of expect_valid holds.
TEST(SkeletonRealMeshes, StrandsBesideALimbAreThreadedIntoIt) {
  reference::EmbreeBackend backend;
  sk::SkeletonOptions off;
  off.unfold_branches = false;
  for (const char* name : {"armadillo.off", "man.off"}) {
    const Mesh mesh = load(name);
    const sk::Skeleton before = sk::extract(mesh, &backend, {}, off);
    const sk::Skeleton after = sk::extract(mesh, &backend, {}, {});
    const auto leaves = [](const sk::Skeleton& s) {
      const auto d = degrees(s);
      return static_cast<std::size_t>(std::count(d.begin(), d.end(), 1));
    };
    std::printf("%s: spur leaves without unfolding %zu of %zu, with %zu of %zu\n", name, spur_branches(before),
                leaves(before), spur_branches(after), leaves(after));
    EXPECT_LT(spur_branches(after), spur_branches(before)) << name;
    EXPECT_LT(leaves(after), leaves(before)) << name;
    EXPECT_EQ(sk::cycle_count(after), sk::cycle_count(before)) << name;
    expect_valid(mesh, after, name);
  }
}

// A limb about as thick as the cell that the sheet test groups centre points in is a curve,
// not a sheet: the armadillo's left forearm and hand (27 % of its nodes were sheet nodes, and
// 8 % of its vertices could not see a curve node) are now curve nodes that every vertex sees.
// A region is a sheet only where its centre points spread wider than the solid is thick. The
// C and S plates keep their sheets (Skeleton.SheetsMakeTheCAndSShapesFullyReliable).
TEST(SkeletonRealMeshes, ThickLimbIsACurveNotASheet) {
  const Mesh mesh = load("armadillo.off");
  ASSERT_EQ(genus(mesh), 0);
  const sk::Skeleton s = extract(mesh);
  EXPECT_LE(sheet_share(s), 0.10);
  EXPECT_GE(s.curve_reliability, 0.95);
  EXPECT_EQ(sk::cycle_count(s), 0);
  EXPECT_EQ(parts(s), 1);
}

// Every curve edge inside the solid on meshes where edges used to leave it (s11fix, eval with
// OpenCL: oblong-shuffled 94/96, boeing 149/151, camel 40/41 before). On oblong-shuffled and
// boeing the edges grazed a triangle's edge and were checked inside as c -> b but counted
// outside as b -> c: the BVH's segment test now traces a segment from its lexicographically
// smaller end. On camel the one bridge whose local detour failed is now routed through the
// solid's centre points. Held with the library's BVH (nodes inside by the rays' winding
// number, the segment crosses no triangle, asked from either end) and, on the consistently
// oriented camel, independently with the winding number at 15 points along each edge
// (oblong-shuffled is not consistently oriented and boeing's parts overlap, so neither the
// winding number nor a parity test at points between the nodes applies there). mpi_triang
// (interlocked block letters, 90 vertices) kept one bridge through the air: its chain of centre
// points was found, but the waypoints' vertices were their nodes' only ones; a waypoint's node
// now takes the nearest vertex of the piece that sees it from a node that keeps one.
// CGAL's bones.off: 26 closed pieces, some of them through each other at the joints. One
// skeleton per piece: every node stands for vertices of one piece, every curve edge joins two
// nodes of one piece, and the skeleton has one part per piece; nodes and curve edges inside the
// solid (the union of the pieces: winding number > 0). Before the skeleton kept to the pieces,
// two nodes held vertices of two bones (a vertex inside the other bone saw that bone's node and
// moved to it) and the edge between them was counted outside.
TEST(SkeletonRealMeshes, OverlappingPiecesGetOneSkeletonEach) {
  const Mesh mesh = load("bones.off");
  const sk::Skeleton s = extract(mesh);
  expect_valid(mesh, s, "bones.off");
  UnionFind pieces(mesh.positions.size());
  for (const Triangle& t : mesh.triangles) pieces.unite(t[0], t[1]), pieces.unite(t[1], t[2]);
  std::vector<std::uint32_t> piece(s.nodes.size());
  for (std::size_t i = 0; i < s.nodes.size(); ++i) {
    std::set<std::uint32_t> of;
    for (std::uint32_t v : s.nodes[i].vertices) of.insert(pieces.find(v));
    EXPECT_EQ(of.size(), 1u) << "node " << i << " stands for vertices of " << of.size() << " pieces";
    piece[i] = *of.begin();
  }
  std::size_t outside = 0;
  for (const auto& e : s.edges) {
    EXPECT_EQ(piece[e[0]], piece[e[1]]) << "edge " << e[0] << "-" << e[1] << " joins two pieces";
    for (int i = 1; i < 16; ++i)
      if (winding_number(mesh, glm::mix(s.nodes[e[0]].position, s.nodes[e[1]].position, static_cast<float>(i) / 16.0f)) < 0.5) {
        ++outside;
        break;
      }
  }
  EXPECT_EQ(outside, 0u);
  EXPECT_EQ(parts(s), 26);
  EXPECT_GT(s.reliability, 0.99);
}

TEST(SkeletonRealMeshes, EveryCurveEdgeStaysInsideTheSolid) {
  for (const char* name : {"oblong-shuffled.off", "boeing.off", "camel.off", "mpi_triang.off"}) {
    const Mesh mesh = load(name);
    const sk::Skeleton s = extract(mesh);
    EXPECT_EQ(sk::cycle_count(s), genus(mesh)) << name;
    EXPECT_EQ(static_cast<std::size_t>(parts(s)), analyze(mesh).components) << name;
    const sk::detail::TriangleBvh bvh(mesh);
    const bool oriented = std::string(name) == "camel.off" || std::string(name) == "mpi_triang.off";
    for (const sk::Node& n : s.nodes) {
      EXPECT_TRUE(bvh.inside(n.position)) << name << ": node outside";
      if (oriented) {
        EXPECT_GT(winding_number(mesh, n.position), 0.5) << name << ": node outside";
      }
    }
    std::size_t blocked = 0, outside = 0;
    for (const auto& e : s.edges) {
      const glm::vec3 a = s.nodes[e[0]].position, b = s.nodes[e[1]].position;
      blocked += bvh.segment_blocked(a, b) || bvh.segment_blocked(b, a);
      for (int i = 1; i < 16 && oriented; ++i) {
        const glm::vec3 p = glm::mix(a, b, static_cast<float>(i) / 16.0f);
        if (winding_number(mesh, p) < 0.5) {
          ++outside;
          break;
        }
      }
    }
    EXPECT_EQ(blocked, 0u) << name << ": curve edges cross the surface";
    EXPECT_EQ(outside, 0u) << name << ": curve edges leave the solid";
  }
}

namespace {

// Distance from p to the closest point of triangle (a, b, c) (Ericson, Real-Time Collision
// Detection, 5.1.5).
float point_triangle(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const glm::vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0f && d2 <= 0.0f) return glm::length(p - a);
  const glm::vec3 bp = p - b;
  const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0f && d4 <= d3) return glm::length(p - b);
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
  const glm::vec3 cp = p - c;
  const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0f && d5 <= d6) return glm::length(p - c);
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f)
    return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  const float denom = 1.0f / (va + vb + vc);
  return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

// How central the curves are, measured on the surface alone: along every curve edge, every
// 1 % of the bounding-box diagonal, the distance from the point to the surface divided by the
// local radius interpolated between the edge's nodes (SDF/2). On the medial axis of a limb that
// ratio is about 1; where an edge cuts across a bend as a chord it falls toward 0.
struct Centrality {
  double mean = 0.0;       // mean ratio
  double near_wall = 0.0;  // share of points closer to the surface than half the local radius
};

Centrality centrality(const Mesh& mesh, const sk::Skeleton& s) {
  const float step = 0.01f * bounding_box(mesh.positions).diagonal();
  double sum = 0.0;
  std::size_t count = 0, close = 0;
  for (const auto& e : s.edges) {
    const sk::Node &a = s.nodes[e[0]], &b = s.nodes[e[1]];
    const int samples = std::max(1, static_cast<int>(std::ceil(glm::length(b.position - a.position) / step)));
    for (int i = 0; i <= samples; ++i) {
      const float t = static_cast<float>(i) / static_cast<float>(samples);
      const glm::vec3 p = a.position + t * (b.position - a.position);
      float d = std::numeric_limits<float>::max();
      for (const Triangle& tri : mesh.triangles)
        d = std::min(d, point_triangle(p, mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]]));
      const float r = (1.0f - t) * a.radius + t * b.radius;
      if (!(r > 0.0f)) continue;
      sum += d / r;
      close += d < 0.5f * r;
      ++count;
    }
  }
  Centrality c;
  if (count > 0) c.mean = sum / static_cast<double>(count), c.near_wall = static_cast<double>(close) / static_cast<double>(count);
  return c;
}

}  // namespace

// Curve edges run through the middle of the limbs, not as chords between grouped nodes
// (SkeletonOptions::section_nodes, s11shape): measured against the surface only. Camel: a
// quadruped whose legs and neck bend (man.off gives 0.687 against 0.594 and 0.229 against 0.352,
// not run here: two more extractions of 17k vertices).
TEST(SkeletonRealMeshes, CurvesRunThroughTheMiddleOfTheLimbs) {
  {
    const char* name = "camel.off";
    SCOPED_TRACE(name);
    const Mesh mesh = load(name);
    reference::EmbreeBackend backend;
    sk::SkeletonOptions chords;
    chords.section_nodes = false;
    const sk::Skeleton with = sk::extract(mesh, &backend, {}, {});
    const sk::Skeleton without = sk::extract(mesh, &backend, {}, chords);
    expect_valid(mesh, with, name);
    EXPECT_EQ(sk::cycle_count(with), sk::cycle_count(without));
    const auto leaves = [](const sk::Skeleton& s) {
      const auto d = degrees(s);
      return std::count(d.begin(), d.end(), 1);
    };
    EXPECT_EQ(leaves(with), leaves(without));  // sections only subdivide edges
    const Centrality on = centrality(mesh, with), off = centrality(mesh, without);
    std::printf("%s: distance to the surface / local radius along the curves: mean %.3f (chords %.3f), "
                "under 0.5: %.3f (chords %.3f); nodes %zu (chords %zu)\n",
                name, on.mean, off.mean, on.near_wall, off.near_wall, with.nodes.size(), without.nodes.size());
    EXPECT_GT(on.mean, off.mean);
    EXPECT_LT(on.near_wall, 0.8 * off.near_wall);  // measured: 0.125 against 0.329
  }
}

// The host octree: overlap test, invariants of the flattened tree, and completeness (every
// triangle that touches a leaf's cell is referenced from it).
#include "sdfkit/core/error.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/opencl/bvh.hpp"
#include "sdfkit/opencl/octree.hpp"

#include <glm/vector_relational.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <set>

using namespace sdfkit;
using sdfkit::cl::build_octree;
using sdfkit::cl::Octree;
using sdfkit::cl::OctreeNode;
using sdfkit::cl::OctreeParams;
using sdfkit::cl::triangle_overlaps_box;

TEST(Octree, TriangleBoxOverlapUsesTheTriangleNotItsBox) {
  const glm::vec3 lo(0, 0, 0), hi(1, 1, 1);
  // Inside, and crossing the box with all vertices outside.
  EXPECT_TRUE(triangle_overlaps_box({0.2f, 0.2f, 0.5f}, {0.8f, 0.2f, 0.5f}, {0.5f, 0.8f, 0.5f}, lo, hi));
  EXPECT_TRUE(triangle_overlaps_box({-5, -5, 0.5f}, {5, -5, 0.5f}, {0, 10, 0.5f}, lo, hi));
  // Far away.
  EXPECT_FALSE(triangle_overlaps_box({2, 2, 2}, {3, 2, 2}, {2, 3, 2}, lo, hi));
  // A diagonal sliver whose bounding box contains the box but which passes beside its corner:
  // the plane x + y = 2.5 misses [0,1]^2 (max x + y = 2).
  EXPECT_FALSE(triangle_overlaps_box({2.5f, 0, -1}, {0, 2.5f, -1}, {0, 2.5f, 2}, {-1, -1, -1}, hi));
  // Touching a face counts (closed sets).
  EXPECT_TRUE(triangle_overlaps_box({1, 0.2f, 0.2f}, {2, 0.2f, 0.2f}, {1, 0.8f, 0.8f}, lo, hi));
}

namespace {

struct Walk {
  std::vector<int> depth;       // per node
  std::vector<std::set<std::uint32_t>> leaf_refs;  // per node (leaves only)
};

Walk walk(const Octree& t) {
  Walk w;
  w.depth.assign(t.nodes.size(), -1);
  w.leaf_refs.resize(t.nodes.size());
  w.depth[0] = 0;
  std::vector<std::uint32_t> todo{0};
  while (!todo.empty()) {
    const std::uint32_t i = todo.back();
    todo.pop_back();
    const OctreeNode& n = t.nodes[i];
    if (n.is_leaf()) {
      w.leaf_refs[i].insert(t.refs.begin() + n.first, t.refs.begin() + n.first + n.count());
      continue;
    }
    EXPECT_NE(n.mask & 0xffu, 0u) << "internal node without children";
    const glm::vec4 c = t.cells[i];
    for (unsigned k = 0; k < 8; ++k) {
      if (!(n.mask & (1u << k))) continue;
      const std::uint32_t child = n.first + static_cast<std::uint32_t>(std::popcount(n.mask & ((1u << k) - 1u)));
      EXPECT_LT(child, t.nodes.size());
      // The child's cell is octant k of the parent's.
      const glm::vec4 cc = t.cells[child];
      EXPECT_FLOAT_EQ(cc.w, c.w * 0.5f);
      for (int a = 0; a < 3; ++a)
        EXPECT_FLOAT_EQ(cc[a], c[a] + ((k >> a) & 1u ? c.w * 0.5f : 0.0f));
      w.depth[child] = w.depth[i] + 1;
      todo.push_back(child);
    }
  }
  return w;
}

}  // namespace

TEST(Octree, LeavesReferenceExactlyTheTrianglesTouchingTheirCell) {
  Mesh mesh = shapes::torus(2.0f, 0.6f, 48, 24);
  // Two degenerate faces: never inserted.
  mesh.triangles.push_back({0, 0, 1});
  mesh.triangles.push_back({0, 1, 1});
  const OctreeParams params{6, 4};
  const Octree t = build_octree(mesh, params);
  const Walk w = walk(t);
  const auto degenerate = degenerate_faces(mesh);
  std::vector<int> seen(mesh.triangles.size(), 0);
  std::size_t leaves = 0;
  for (std::size_t i = 0; i < t.nodes.size(); ++i) {
    ASSERT_GE(w.depth[i], 0) << "node " << i << " is not reachable";
    EXPECT_LE(w.depth[i], params.max_depth);
    if (!t.nodes[i].is_leaf()) continue;
    ++leaves;
    if (w.depth[i] < params.max_depth) {
      EXPECT_LE(t.nodes[i].count(), 4u);
    }
    const glm::vec3 lo(t.cells[i]), hi = lo + glm::vec3(t.cells[i].w);
    const glm::vec3 pad(t.cells[i].w * 1e-3f);
    for (std::uint32_t f = 0; f < mesh.triangles.size(); ++f) {
      const auto& tri = mesh.triangles[f];
      const glm::vec3 a = mesh.positions[tri[0]], b = mesh.positions[tri[1]], c = mesh.positions[tri[2]];
      const bool referenced = w.leaf_refs[i].count(f) > 0;
      if (referenced) {
        ++seen[f];
        EXPECT_FALSE(degenerate[f]);
        EXPECT_TRUE(triangle_overlaps_box(a, b, c, lo - pad, hi + pad)) << "face " << f;
      } else if (!degenerate[f]) {
        // Not referenced: then it does not reach into the cell (shrunk against rounding).
        EXPECT_FALSE(triangle_overlaps_box(a, b, c, lo + pad, hi - pad)) << "face " << f;
      }
    }
  }
  EXPECT_EQ(leaves, t.leaf_count);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
    EXPECT_EQ(seen[f] > 0, !degenerate[f]) << "face " << f;
  EXPECT_EQ(t.inserted_triangles, mesh.triangles.size() - 2);
  EXPECT_GT(t.depth, 2);
}

TEST(Octree, RejectsBadParameters) {
  const Mesh mesh = shapes::icosphere(1.0f, 1);
  EXPECT_THROW(build_octree(mesh, {0, 8}), InputError);
  EXPECT_THROW(build_octree(mesh, {17, 8}), InputError);
  EXPECT_THROW(build_octree(mesh, {8, 0}), InputError);
}

// The BVH: every non-degenerate triangle in exactly one leaf, boxes nest and contain their
// triangles, depth within the device stack. A small mesh (built on one thread) and one large
// enough for the root's subtrees to be built on two threads and spliced.
void expect_valid_bvh(const sdfkit::cl::Bvh& b, const Mesh& mesh) {
  using sdfkit::cl::BvhNode;
  const auto degenerate = degenerate_faces(mesh);
  std::vector<int> seen(mesh.triangles.size(), 0);
  std::vector<std::pair<std::uint32_t, int>> todo{{0, 0}};
  std::size_t leaves = 0;
  int depth = 0;
  auto inside = [](const BvhNode& outer, glm::vec3 p) {
    return glm::all(glm::lessThanEqual(outer.min, p)) && glm::all(glm::lessThanEqual(p, outer.max));
  };
  while (!todo.empty()) {
    const auto [i, d] = todo.back();
    todo.pop_back();
    depth = std::max(depth, d);
    const BvhNode& n = b.nodes[i];
    if (n.is_leaf()) {
      ++leaves;
      for (std::uint32_t k = n.first_or_second; k < n.first_or_second + n.triangles(); ++k) {
        const std::uint32_t f = b.order[k];
        ++seen[f];
        for (std::uint32_t v : mesh.triangles[f]) EXPECT_TRUE(inside(n, mesh.positions[v]));
      }
      continue;
    }
    for (std::uint32_t c : {i + 1, n.first_or_second}) {
      ASSERT_LT(c, b.nodes.size());
      EXPECT_TRUE(inside(n, b.nodes[c].min) && inside(n, b.nodes[c].max));
      todo.push_back({c, d + 1});
    }
  }
  EXPECT_EQ(leaves, b.leaf_count);
  EXPECT_EQ(depth, b.depth);
  EXPECT_LT(depth, 72);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) EXPECT_EQ(seen[f], degenerate[f] ? 0 : 1) << f;
}

Mesh with_degenerate(Mesh mesh) {
  mesh.triangles.push_back({0, 0, 1});
  return mesh;
}

TEST(Bvh, LeavesPartitionTheTrianglesAndBoxesNest) {
  for (const Mesh& m : {with_degenerate(shapes::torus(2.0f, 0.6f, 48, 24)),      // 2304 triangles
                        with_degenerate(shapes::torus(2.0f, 0.6f, 192, 96))}) {  // two threads
    expect_valid_bvh(sdfkit::cl::build_bvh(m, {4}), m);
  }
}

// A refit keeps the tree and the triangle order, and its boxes again nest and contain the
// moved triangles; its SAH cost is that of the same tree over the new boxes (a fresh build of
// the moved mesh is no worse).
TEST(Bvh, RefitBoxesContainTheMovedTriangles) {
  const Mesh before = with_degenerate(shapes::torus(2.0f, 0.6f, 48, 24));
  Mesh after = before;
  for (glm::vec3& p : after.positions) p = glm::vec3(p.x * 0.5f, p.y + 0.3f * p.x * p.x, p.z * 2.0f);
  sdfkit::cl::Bvh b = sdfkit::cl::build_bvh(before, {4});
  const auto order = b.order;
  const double built = sdfkit::cl::sah_cost(b);
  ASSERT_TRUE(sdfkit::cl::refit_bvh(b, after));
  EXPECT_EQ(b.order, order);
  expect_valid_bvh(b, after);
  EXPECT_GT(sdfkit::cl::sah_cost(b), 0.0);
  EXPECT_LE(sdfkit::cl::sah_cost(sdfkit::cl::build_bvh(after, {4})), 1.01 * sdfkit::cl::sah_cost(b));
  // Refitting to the build's own positions gives the build's boxes.
  ASSERT_TRUE(sdfkit::cl::refit_bvh(b, before));
  EXPECT_NEAR(sdfkit::cl::sah_cost(b), built, 1e-9 * built);
}

// Every box of a build is exactly the padded union of its triangles' boxes: a refit to the same
// positions (boxes recomputed bottom-up from the triangles, an independent computation) leaves
// every node bit for bit as built. The build takes a node's bounds from its parent's partition
// instead of measuring them again; this mesh (540k triangles) is large enough for the parallel
// binning and the subtree tasks, and the leaf size is the bundle tracer's.
TEST(Bvh, BuildBoxesAreTheUnionsOfTheirTriangles) {
  const Mesh mesh = with_degenerate(shapes::torus(2.0f, 0.6f, 600, 450));
  ASSERT_GT(mesh.triangles.size(), std::size_t{1} << 19);
  for (const sdfkit::cl::BvhParams params : {sdfkit::cl::BvhParams{16, 3.0f}, sdfkit::cl::BvhParams{4, 1.0f}}) {
    const sdfkit::cl::Bvh built = sdfkit::cl::build_bvh(mesh, params);
    expect_valid_bvh(built, mesh);  // its parts laid out on all threads at this size
    sdfkit::cl::Bvh refit = built;
    ASSERT_TRUE(sdfkit::cl::refit_bvh(refit, mesh));
    ASSERT_EQ(refit.nodes.size(), built.nodes.size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < built.nodes.size(); ++i)
      differ += built.nodes[i].min != refit.nodes[i].min || built.nodes[i].max != refit.nodes[i].max;
    EXPECT_EQ(differ, 0u) << "of " << built.nodes.size() << " nodes";
  }
}

// A triangle left out as degenerate that gets an area cannot be refit into the tree.
TEST(Bvh, RefitRefusesATriangleThatIsNoLongerDegenerate) {
  Mesh mesh = shapes::torus(2.0f, 0.6f, 24, 12);
  const auto n = static_cast<std::uint32_t>(mesh.positions.size());
  mesh.positions.push_back({0, 0, 0});
  mesh.positions.push_back({1, 0, 0});
  mesh.positions.push_back({2, 0, 0});  // collinear: degenerate
  mesh.triangles.push_back({n, n + 1, n + 2});
  sdfkit::cl::Bvh b = sdfkit::cl::build_bvh(mesh, {4});
  Mesh moved = mesh;
  EXPECT_TRUE(sdfkit::cl::refit_bvh(b, moved));
  moved.positions[n + 1].y = 1.0f;
  EXPECT_FALSE(sdfkit::cl::refit_bvh(b, moved));
}

// The build's threads share out the top's splits and the subtree tasks as they come; a node's
// split depends only on its own triangles, so any thread count gives the same tree, node for
// node and bit for bit, and the same triangle order. 1.06M triangles: the top is split into
// parts of 1/16 of the triangles per thread, as at 13M.
TEST(Bvh, SameTreeOnAnyThreadCount) {
  const Mesh mesh = with_degenerate(shapes::torus(2.0f, 0.6f, 1024, 520));
  ASSERT_GE(mesh.triangles.size(), std::size_t{1} << 20);
  const sdfkit::cl::Bvh one = sdfkit::cl::build_bvh(mesh, {16, 3.0f, 1});
  expect_valid_bvh(one, mesh);
  for (int threads : {3, 0}) {  // 0: all (two on the 2-core VM)
    const sdfkit::cl::Bvh many = sdfkit::cl::build_bvh(mesh, {16, 3.0f, threads});
    ASSERT_EQ(many.nodes.size(), one.nodes.size()) << threads;
    EXPECT_EQ(std::memcmp(many.nodes.data(), one.nodes.data(), one.nodes.size() * sizeof(one.nodes[0])), 0) << threads;
    EXPECT_EQ(many.order, one.order) << threads;
    EXPECT_EQ(many.depth, one.depth) << threads;
    EXPECT_EQ(many.leaf_count, one.leaf_count) << threads;
  }
  EXPECT_THROW(sdfkit::cl::build_bvh(mesh, {16, 3.0f, -1}), InputError);
}

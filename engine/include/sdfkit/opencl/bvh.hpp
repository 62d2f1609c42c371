#pragma once
// A bounding-volume hierarchy over a triangle mesh, built on the host with binned SAH and
// flattened into the arrays the OpenCL tracer walks (cl/sdf_trace.cl, SDFKIT_BVH). The default
// acceleration structure of the OpenCL backend: on CPUs (PoCL) its tight boxes cost fewer
// triangle tests per ray than the octree's cubic cells.
//
// * Every non-degenerate triangle is in exactly one leaf; degenerate triangles are left out.
// * Boxes are padded by 1e-6 of the mesh's largest coordinate (flat boxes of axis-aligned
//   faces stay hittable despite rounding in the slab tests).
// * A node is split along the best of 3 axes x 16 centroid bins by the surface-area heuristic
//   (`traversal_cost` per node visit, 1 per triangle test); it stays a leaf when it holds at
//   most `leaf_size` triangles and no split is cheaper than testing them all. Nodes with more triangles are
//   always split (at the object median when the centroids coincide), and below depth 40 the
//   split is the object median, so the depth stays under 72 for up to 2^32 triangles (the
//   device stack holds 96).
// * Layout: depth-first; an internal node's first child is the next node, `second` names the
//   other; a leaf names its first triangle (in `order`, leaf by leaf) and its count.

#include "sdfkit/core/mesh.hpp"

#include <cstdint>
#include <vector>

namespace sdfkit::cl {

struct BvhParams {
  int leaf_size = 4;           // >= 1
  float traversal_cost = 1.0f;  // a node visit in triangle tests, > 0
  int threads = 0;              // build threads, 0 = all; the tree is the same for any count
};

// One flattened node, as the device reads it (two float4: min + word, max + word).
struct BvhNode {
  glm::vec3 min{0.0f};
  std::uint32_t first_or_second = 0;  // leaf: first triangle in `order`; internal: second child
  glm::vec3 max{0.0f};
  std::uint32_t count = 0;            // leaf: kLeafBit | triangles; internal: 0
  static constexpr std::uint32_t kLeafBit = 0x80000000u;
  bool is_leaf() const { return (count & kLeafBit) != 0; }
  std::uint32_t triangles() const { return count & ~kLeafBit; }
};
static_assert(sizeof(BvhNode) == 32);

struct Bvh {
  std::vector<BvhNode> nodes;
  std::vector<std::uint32_t> order;  // face indices, leaf by leaf
  int depth = 0;
  std::size_t leaf_count = 0;
};

// Builds the BVH of `mesh`; a mesh without non-degenerate triangles gives one empty leaf.
// Throws InputError for params out of range.
Bvh build_bvh(const Mesh& mesh, const BvhParams& params);

// Recomputes every box of `bvh` (built for a mesh with the same triangles) from the mesh's
// current positions, bottom-up, keeping the tree and the triangle order; padding as in a
// build. Returns false, leaving `bvh` unusable, when a triangle that the build left out as
// degenerate is not degenerate any more (the tree lacks it): rebuild then.
bool refit_bvh(Bvh& bvh, const Mesh& mesh);

// The tree's surface-area cost relative to its root box: the sum over internal nodes of their
// box area plus, over leaves, box area times triangle count, divided by the root's area (the
// expected box and triangle tests of a ray through the root). A refit tree whose cost has grown
// well past its build's has boxes that overlap more and more: rebuild it.
double sah_cost(const Bvh& bvh);

}  // namespace sdfkit::cl

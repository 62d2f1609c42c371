#pragma once
// A sparse octree over a triangle mesh, built on the host and flattened into the arrays the
// OpenCL tracer walks (see cl/sdf_trace.cl).
//
// * The root is the cube around the mesh's bounding box (its longest side, centred, padded by
//   1e-4 of that side so faces on the box never sit exactly on the root's boundary).
// * A node is split into its 8 octants while it holds more than `leaf_size` triangles and is
//   shallower than `max_depth` (root depth 0). Octants that no triangle touches are not stored.
// * A triangle touching several octants is referenced from every leaf it overlaps. Overlap is
//   the exact separating-axis triangle/box test (Akenine-Möller 2001), not the triangle's
//   bounding box, so a long diagonal sliver is not referenced from cells it only boxes.
// * A split that leaves some child with every triangle of its parent (a pile of triangles
//   through one point) still descends; max_depth bounds it.
// * Degenerate triangles (sdfkit::triangle_is_degenerate) are not inserted: they are never hit.
//
// Flattened layout: nodes[0] is the root; the non-empty children of an internal node are stored
// next to each other, in octant order, starting at `first`; child octant k (bit 0 = +x half,
// bit 1 = +y, bit 2 = +z) sits at first + popcount(mask & ((1 << k) - 1)).

#include "sdfkit/core/mesh.hpp"

#include <glm/vec4.hpp>

#include <cstdint>
#include <vector>

namespace sdfkit::cl {

struct OctreeParams {
  int max_depth = 10;  // deepest level (root = 0); 1..16
  int leaf_size = 8;   // a node with at most this many triangles stays a leaf; >= 1
};

// One flattened node, as the device reads it (a uint2).
struct OctreeNode {
  // Internal: index of the first stored child. Leaf: offset of its triangles in `refs`.
  std::uint32_t first = 0;
  // Internal: bits 0..7 = which octants are stored. Leaf: kLeafBit | triangle count.
  std::uint32_t mask = 0;
  static constexpr std::uint32_t kLeafBit = 0x80000000u;
  bool is_leaf() const { return (mask & kLeafBit) != 0; }
  std::uint32_t count() const { return mask & ~kLeafBit; }
};

struct Octree {
  std::vector<OctreeNode> nodes;
  std::vector<glm::vec4> cells;      // per node: xyz = the cell's minimum corner, w = its side
  std::vector<std::uint32_t> refs;   // leaf triangle lists (face indices into the mesh)
  glm::vec3 root_min{0.0f};
  float root_size = 0.0f;
  int depth = 0;                     // deepest leaf actually built
  std::size_t leaf_count = 0;
  std::size_t inserted_triangles = 0;  // non-degenerate triangles
  std::size_t bytes() const;           // size of nodes + cells + refs
};

// Builds the octree of `mesh` (positions and triangles; degenerate triangles skipped).
// Throws InputError on params out of range.
Octree build_octree(const Mesh& mesh, const OctreeParams& params);

// True when triangle (a, b, c) and the axis-aligned box [lo, hi] share a point (closed sets),
// by the separating-axis theorem on the 13 axes.
bool triangle_overlaps_box(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                           const glm::vec3& lo, const glm::vec3& hi);

}  // namespace sdfkit::cl

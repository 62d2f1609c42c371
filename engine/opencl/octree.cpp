#include "sdfkit/opencl/octree.hpp"

#include "sdfkit/core/error.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <string>

namespace sdfkit::cl {

std::size_t Octree::bytes() const {
  return nodes.size() * sizeof(OctreeNode) + cells.size() * sizeof(glm::vec4) +
         refs.size() * sizeof(std::uint32_t);
}

namespace {

// Separated along axis `l` when the triangle's projection misses the box's [-r, r].
bool separated(const glm::vec3& l, const glm::vec3& v0, const glm::vec3& v1, const glm::vec3& v2,
               const glm::vec3& half) {
  const float p0 = glm::dot(l, v0), p1 = glm::dot(l, v1), p2 = glm::dot(l, v2);
  const float r = half.x * std::fabs(l.x) + half.y * std::fabs(l.y) + half.z * std::fabs(l.z);
  return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
}

}  // namespace

bool triangle_overlaps_box(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                           const glm::vec3& lo, const glm::vec3& hi) {
  const glm::vec3 centre = (lo + hi) * 0.5f, half = (hi - lo) * 0.5f;
  const glm::vec3 v0 = a - centre, v1 = b - centre, v2 = c - centre;
  // The box's face normals: the triangle's bounding box against the box.
  for (int k = 0; k < 3; ++k) {
    if (std::min({v0[k], v1[k], v2[k]}) > half[k] || std::max({v0[k], v1[k], v2[k]}) < -half[k])
      return false;
  }
  // The triangle's plane.
  const glm::vec3 e0 = v1 - v0, e1 = v2 - v1, e2 = v0 - v2;
  if (separated(glm::cross(e0, e1), v0, v1, v2, half)) return false;
  // The nine edge x box-axis cross products.
  const std::array<glm::vec3, 3> edges{e0, e1, e2};
  const std::array<glm::vec3, 3> axes{glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1)};
  for (const glm::vec3& e : edges)
    for (const glm::vec3& u : axes)
      if (separated(glm::cross(u, e), v0, v1, v2, half)) return false;
  return true;
}

namespace {

struct Builder {
  const Mesh& mesh;
  OctreeParams params;
  std::vector<glm::vec3> tri_min, tri_max;  // per face bounding boxes
  Octree out;

  const glm::vec3& vertex(std::uint32_t face, int corner) const {
    return mesh.positions[mesh.triangles[face][static_cast<std::size_t>(corner)]];
  }

  // Fills node `index` (already allocated) for the cell (lo, size) holding `tris`.
  void build(std::uint32_t index, glm::vec3 lo, float size, int depth,
             std::vector<std::uint32_t> tris) {
    out.cells[index] = glm::vec4(lo, size);
    out.depth = std::max(out.depth, depth);
    if (tris.size() <= static_cast<std::size_t>(params.leaf_size) || depth >= params.max_depth) {
      out.nodes[index].first = static_cast<std::uint32_t>(out.refs.size());
      out.nodes[index].mask = OctreeNode::kLeafBit | static_cast<std::uint32_t>(tris.size());
      out.refs.insert(out.refs.end(), tris.begin(), tris.end());
      ++out.leaf_count;
      return;
    }
    const float half = size * 0.5f;
    const glm::vec3 mid = lo + glm::vec3(half);
    // Conservative padding so rounding in the overlap test never drops a triangle from a cell
    // a ray may enter to hit it; an extra reference only costs a test.
    const float pad = size * 1e-5f;
    std::array<std::vector<std::uint32_t>, 8> child;
    for (std::uint32_t f : tris) {
      // Which halves the triangle's box reaches along each axis.
      unsigned low = 0, high = 0;
      for (int k = 0; k < 3; ++k) {
        if (tri_min[f][k] <= mid[k] + pad) low |= 1u << k;
        if (tri_max[f][k] >= mid[k] - pad) high |= 1u << k;
      }
      const bool single = std::popcount(low & high) == 0;
      for (unsigned oct = 0; oct < 8; ++oct) {
        // Octant bit k set = the upper half along axis k.
        if ((oct & ~high & 7u) != 0 || (~oct & ~low & 7u) != 0) continue;
        if (!single) {
          glm::vec3 clo = lo, chi = mid;
          for (int k = 0; k < 3; ++k)
            if (oct & (1u << k)) {
              clo[k] = mid[k];
              chi[k] = lo[k] + size;
            }
          if (!triangle_overlaps_box(vertex(f, 0), vertex(f, 1), vertex(f, 2), clo - pad,
                                     chi + pad))
            continue;
        }
        child[oct].push_back(f);
      }
    }
    tris.clear();
    tris.shrink_to_fit();
    std::uint32_t mask = 0;
    for (unsigned oct = 0; oct < 8; ++oct)
      if (!child[oct].empty()) mask |= 1u << oct;
    const auto first = static_cast<std::uint32_t>(out.nodes.size());
    out.nodes[index].first = first;
    out.nodes[index].mask = mask;
    out.nodes.resize(out.nodes.size() + static_cast<std::size_t>(std::popcount(mask)));
    out.cells.resize(out.nodes.size());
    std::uint32_t slot = first;
    for (unsigned oct = 0; oct < 8; ++oct) {
      if (child[oct].empty()) continue;
      glm::vec3 clo = lo;
      for (int k = 0; k < 3; ++k)
        if (oct & (1u << k)) clo[k] = mid[k];
      build(slot++, clo, half, depth + 1, std::move(child[oct]));
    }
  }
};

}  // namespace

Octree build_octree(const Mesh& mesh, const OctreeParams& params) {
  if (params.max_depth < 1 || params.max_depth > 16)
    throw InputError("the octree depth must be between 1 and 16, got " +
                     std::to_string(params.max_depth));
  if (params.leaf_size < 1)
    throw InputError("the octree leaf size must be at least 1, got " +
                     std::to_string(params.leaf_size));
  Builder b{mesh, params, {}, {}, {}};
  const std::vector<std::uint8_t> degenerate = degenerate_faces(mesh);
  std::vector<std::uint32_t> tris;
  tris.reserve(mesh.triangles.size());
  b.tri_min.resize(mesh.triangles.size());
  b.tri_max.resize(mesh.triangles.size());
  Aabb box;
  bool first = true;
  for (std::uint32_t f = 0; f < mesh.triangles.size(); ++f) {
    if (degenerate[f]) continue;
    const glm::vec3 &p = b.vertex(f, 0), &q = b.vertex(f, 1), &r = b.vertex(f, 2);
    b.tri_min[f] = glm::min(p, glm::min(q, r));
    b.tri_max[f] = glm::max(p, glm::max(q, r));
    box.min = first ? b.tri_min[f] : glm::min(box.min, b.tri_min[f]);
    box.max = first ? b.tri_max[f] : glm::max(box.max, b.tri_max[f]);
    first = false;
    tris.push_back(f);
  }
  b.out.inserted_triangles = tris.size();
  const glm::vec3 extent = box.extent();
  float side = std::max({extent.x, extent.y, extent.z});
  if (!(side > 0.0f)) side = 1.0f;
  side *= 1.0f + 2e-4f;
  b.out.root_size = side;
  b.out.root_min = box.center() - glm::vec3(0.5f * side);
  b.out.nodes.resize(1);
  b.out.cells.resize(1);
  b.build(0, b.out.root_min, side, 0, std::move(tris));
  return std::move(b.out);
}

}  // namespace sdfkit::cl

#pragma once
// A small CPU bounding-volume hierarchy over a mesh's triangles, for the visibility and
// inside/outside questions of skeleton extraction (is a segment inside the solid? does a point
// lie inside?). Not an SDF backend: the SDF comes from the engine's backends.

#include "sdfkit/core/mesh.hpp"

#include <cstdint>
#include <vector>

namespace sdfkit::skeleton::detail {

class TriangleBvh {
public:
  // Builds over the mesh's non-degenerate triangles (median split, leaves of <= 4 triangles).
  explicit TriangleBvh(const Mesh& mesh);

  struct Hit {
    bool found = false;
    float t = 0.0f;          // distance along the unit direction
    std::uint32_t face = 0;  // index into mesh.triangles
  };
  // Closest hit of the ray o + t*dir (dir unit), t in (tmin, tmax]; faces that use vertex
  // `skip_vertex` are ignored (pass UINT32_MAX to ignore none).
  Hit closest(const glm::vec3& o, const glm::vec3& dir, float tmin, float tmax,
              std::uint32_t skip_vertex = UINT32_MAX) const;
  // True when the open segment a -> b crosses a triangle (faces using skip_vertex ignored);
  // symmetric: (a, b) and (b, a) give the same answer.
  bool segment_blocked(const glm::vec3& a, const glm::vec3& b,
                       std::uint32_t skip_vertex = UINT32_MAX) const;
  // Inside test for a closed mesh: the majority vote of three rays in fixed skew directions,
  // each inside when it crosses the surface an odd number of times. (Parity, not the
  // orientation of the closest hit: CGAL's cow has a region where the closest-hit test called
  // a point inside that the winding number puts outside.)
  bool inside(const glm::vec3& p) const;

  const Mesh& mesh() const { return *mesh_; }
  const std::vector<glm::vec3>& normals() const { return normals_; }

private:
  struct Node {
    glm::vec3 lo, hi;
    std::uint32_t first;  // leaf: first index into order_; inner: index of the right child
    std::uint32_t count;  // leaf: number of triangles; inner: 0
  };
  std::uint32_t build(std::uint32_t begin, std::uint32_t end, std::vector<glm::vec3>& centroids);
  template <class Visit>
  void traverse(const glm::vec3& o, const glm::vec3& dir, float tmin, float& tmax,
                Visit&& visit) const;

  const Mesh* mesh_;
  std::vector<glm::vec3> normals_;
  std::vector<std::uint32_t> order_;
  std::vector<Node> nodes_;
};

}  // namespace sdfkit::skeleton::detail

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
  // True when the open segment a -> b crosses a triangle (faces using skip_vertex ignored; with
  // `component`, faces of other mesh components too, see component()); symmetric: (a, b) and
  // (b, a) give the same answer.
  bool segment_blocked(const glm::vec3& a, const glm::vec3& b, std::uint32_t skip_vertex = UINT32_MAX,
                       std::uint32_t component = UINT32_MAX) const;
  // The solid is where the winding number of the closed surface is not 0: the inside of each
  // closed piece, the union where pieces overlap (two bones through each other: bones.off),
  // without a cavity (an inner piece wound the other way). On a mesh of closed pieces that
  // neither overlap nor nest this is the inside of the one piece a point is in.
  //
  // Winding number of p: along each of three rays in fixed skew directions, the surface's
  // exits minus its entries (the sign of the face normal along the ray), the majority of the
  // three votes "not 0" deciding inside(). (A crossing count, not the orientation of the
  // closest hit: CGAL's cow has a region where the closest-hit test called a point inside that
  // the winding number puts outside.)
  bool inside(const glm::vec3& p) const;
  // True when the segment a -> b leaves the solid: a or b is outside, or the winding number
  // falls to 0 at a crossing between them. Unlike segment_blocked, entering a second,
  // overlapping piece is not leaving. Symmetric like segment_blocked.
  bool segment_leaves(const glm::vec3& a, const glm::vec3& b) const;

  // Per vertex: its component (connected over triangles), named by the component's lowest
  // vertex index.
  const std::vector<std::uint32_t>& component() const { return component_; }

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

  // Winding number of p along the ray p + t d (exits minus entries over t > 0).
  int ray_winding(const glm::vec3& p, const glm::vec3& d) const;

  const Mesh* mesh_;
  std::vector<glm::vec3> normals_;
  std::vector<std::uint32_t> component_;
  std::vector<std::uint32_t> order_;
  std::vector<Node> nodes_;
};

}  // namespace sdfkit::skeleton::detail

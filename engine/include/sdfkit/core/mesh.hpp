#pragma once
// The triangle mesh every backend sees: welded positions and triangles (counter-clockwise
// seen from outside = outward normal), plus the geometric helpers shared by all backends.

#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace sdfkit {

using Triangle = std::array<std::uint32_t, 3>;

struct Mesh {
  std::vector<glm::vec3> positions;  // V positions in model units
  std::vector<Triangle> triangles;   // F triangles, indices into positions

  std::size_t vertex_count() const { return positions.size(); }
  std::size_t face_count() const { return triangles.size(); }
};

struct Aabb {
  glm::vec3 min{0.0f};
  glm::vec3 max{0.0f};
  glm::vec3 extent() const { return max - min; }
  glm::vec3 center() const { return (min + max) * 0.5f; }
  float diagonal() const;
};

// Bounding box of the positions. Empty input gives a zero box at the origin.
Aabb bounding_box(std::span<const glm::vec3> positions);

// A triangle is degenerate when twice its area is at most kDegenerateRatio times the square of
// its longest edge (a needle or a point; the threshold sits well above float rounding of the
// cross product). Degenerate triangles get no normal, are never ray targets and never ray
// origins, and never produce NaN.
inline constexpr float kDegenerateRatio = 1e-6f;
bool triangle_is_degenerate(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c);

// Per face: 1 where the triangle is degenerate (see above) or uses an index out of range.
std::vector<std::uint8_t> degenerate_faces(const Mesh& mesh);

// Unit outward face normals, F entries; zero for degenerate faces.
std::vector<glm::vec3> face_normals(const Mesh& mesh);

// Face areas, F entries, in squared model units; zero for degenerate faces.
std::vector<float> face_areas(const Mesh& mesh);

// Unit outward vertex normals, V entries: the sum of the incident non-degenerate faces' normals
// weighted by the face's interior angle at the vertex (Thürmer & Wüthrich 1998). The angle
// weighting makes the normal independent of how a flat region is triangulated. Zero for vertices
// that touch no non-degenerate face (isolated vertices), and for the rare vertex whose weighted
// normals cancel exactly.
std::vector<glm::vec3> vertex_normals(const Mesh& mesh);

// Face centroids (barycenters), F entries.
std::vector<glm::vec3> face_centroids(const Mesh& mesh);

// Throws InputError when the mesh has no triangles, an index out of range, or a non-finite
// coordinate. `what` names the source in the message (a file path, "generated mesh").
void validate_mesh(const Mesh& mesh, const std::string& what);

// Applies a 4x4 column-major affine transform to the positions (for tests: rotation invariance).
Mesh transformed(const Mesh& mesh, const float (&m)[16]);

}  // namespace sdfkit

namespace sdfkit {

// One step of midpoint subdivision: every triangle becomes four, new vertices at edge midpoints
// (shared between the two faces of an edge). The surface does not move, so SDF values stay the
// same while the mesh grows about four times: benchmark meshes at paper sizes.
Mesh subdivide_midpoint(const Mesh& mesh);

}  // namespace sdfkit

#pragma once
// Analytic test shapes generated at any resolution, closed and outward-oriented, each with a
// signed distance function (negative inside) for analytic ray casting in tests.

#include "sdfkit/core/mesh.hpp"

#include <functional>
#include <vector>

namespace sdfkit::shapes {

// UV sphere of `radius`, `segments` around (>= 3), `rings` from pole to pole (>= 2).
Mesh sphere(float radius, int segments, int rings);
// Icosphere (subdivided icosahedron): near-uniform triangles. subdivisions >= 0.
Mesh icosphere(float radius, int subdivisions);
// Cylinder along z from -length/2 to length/2 with flat caps; `segments` around, `stacks`
// along, `cap_rings` concentric rings on each cap.
Mesh capped_cylinder(float radius, float length, int segments, int stacks, int cap_rings);
// Capsule along z: cylinder of `radius` and `length` between hemispherical ends.
Mesh capsule(float radius, float length, int segments, int stacks);
// Torus around z: tube radius `minor` at distance `major` from the axis.
Mesh torus(float major, float minor, int major_segments, int minor_segments);
// Axis-aligned box centred at the origin with sizes (sx, sy, sz), each face an n x n grid.
Mesh box(float sx, float sy, float sz, int n);

// Not closed: the open side of a cylinder of `radius` around z, from z = 0 to `height`, as a
// regular grid (texture-space tests and benchmarks map it analytically): vertex (i, j) is
// j * segments + i, at angle 2 pi i / segments and height j * height / stacks. segments >= 3,
// stacks >= 1.
Mesh open_cylinder(float radius, float height, int segments, int stacks);

// The paper's Figure 7 model: a circle swept along a planar cubic Bezier curve, its diameter
// growing linearly with arc length from `d0` to `d1` (2 to 20 in the paper), flat caps.
struct SweptTube {
  Mesh mesh;
  std::vector<float> true_diameter;  // per vertex: the local diameter at that vertex's ring
  std::vector<float> arc_fraction;   // per vertex: arc length from the start / total (caps: 0/1)
  std::vector<std::uint8_t> on_cap;  // per vertex: 1 for cap vertices (centre and cap rings)
};
SweptTube swept_tube(float d0 = 2.0f, float d1 = 20.0f, int rings = 200, int segments = 64);

// Signed distance functions of the ideal shapes above (negative inside).
float sphere_sdf(const glm::vec3& p, float radius);
float capped_cylinder_sdf(const glm::vec3& p, float radius, float length);
float torus_sdf(const glm::vec3& p, float major, float minor);
float box_sdf(const glm::vec3& p, const glm::vec3& size);
float capsule_sdf(const glm::vec3& p, float radius, float length);

}  // namespace sdfkit::shapes

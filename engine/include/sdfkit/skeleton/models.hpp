#pragma once
// Procedural closed meshes for skeleton tests and benchmarks, each with its known medial
// geometry: thick curved plates with non-convex C and S cross-sections (where a curve skeleton
// is not reliable), a five-armed star with arms of different thickness, a genus-2 solid. Also
// the mesher they share: an implicit surface polygonized by marching tetrahedra and relaxed.

#include "sdfkit/core/mesh.hpp"

#include <array>
#include <functional>
#include <vector>

namespace sdfkit::skeleton::models {

using Implicit = std::function<float(const glm::vec3&)>;  // signed distance, negative inside

// Polygonizes the zero set of `fn` inside `box` on a grid of cubic cells of edge `cell` (each
// cube split into six tetrahedra along its main diagonal, so the surface is closed and
// manifold), then relaxes it: `relax` rounds of moving every vertex to the mean of its
// neighbours and projecting it back onto the zero set by Newton steps along the gradient.
// `fn` must be positive on the box's boundary. Triangles face outward (toward fn > 0).
Mesh implicit_surface(const Implicit& fn, const Aabb& box, float cell, int relax = 8);

// A straight bar along z of length `height` whose cross-section is a band of `thickness`
// around a planar centre curve: a circular arc of `radius` over `arc_degrees` (C) or two such
// arcs of opposite bending joined tangentially (S). `cell` is the target edge length.
struct Plate {
  Mesh mesh;
  std::vector<glm::vec3> centre_curve;  // the cross-section's centre curve at z = 0
};
Plate c_shape(float radius = 0.6f, float arc_degrees = 270.0f, float thickness = 0.2f,
              float height = 3.0f, float cell = 0.1f);
Plate s_shape(float radius = 0.5f, float arc_degrees = 225.0f, float thickness = 0.2f,
              float height = 3.0f, float cell = 0.1f);

// Segments of a known medial axis (curve part), model units.
using Segment = std::array<glm::vec3, 2>;
// Distance from p to the nearest of the segments.
float distance_to(const std::vector<Segment>& axis, const glm::vec3& p);

// Five capsule arms in the xy plane from a central ball, arm k of radius radii[k] pointing at
// 72*k degrees with its end-ball centre at distance `arm_length` from the origin, joined by a
// smooth union. `axis`: the five segments from the origin to the end-ball centres.
struct Star {
  Mesh mesh;
  std::vector<Segment> axis;
  Implicit fn;
};
Star five_armed_star(std::array<float, 5> radii = {0.18f, 0.24f, 0.30f, 0.36f, 0.42f},
                     float arm_length = 2.0f, float centre_radius = 0.55f, float cell = 0.15f);

// Two solid tori (tube radius `minor`, ring radius `major`) in the xy plane with centres at
// x = -/+ separation/2, fused where they overlap by a smooth union: genus 2. `axis`: the two
// rings as polylines of 64 segments each.
struct Genus2 {
  Mesh mesh;
  std::vector<Segment> axis;
  Implicit fn;
};
Genus2 genus2(float major = 1.0f, float minor = 0.3f, float separation = 2.2f, float cell = 0.12f);

}  // namespace sdfkit::skeleton::models

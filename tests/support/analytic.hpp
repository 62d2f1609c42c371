#pragma once
// The SDF estimator evaluated on ideal implicit shapes: each ray of the shared definition is
// sphere-traced through the shape's exact signed distance function (no triangles), hit normals
// come from its gradient, and the shared gather makes the value. This is the "exact expected
// value of this estimator" that the tessellated backends are held to.

#include "sdfkit/core/sdf.hpp"

#include <functional>
#include <string>

namespace sdfkit::test {

using ImplicitFn = std::function<float(const glm::vec3&)>;

// `scale` is a length of the shape's size (for tolerances); rays that leave through nothing
// within 4 * scale count as misses.
RawSdf analytic_sdf(const SdfQuery& query, const SdfOptions& options, const ImplicitFn& sdf,
                    float scale);

// The estimator's exact value on a sphere of radius R, per point, with exact normals: a ray at
// angle theta to the inward normal travels 2 R cos(theta); under the paper's rule only
// theta <= 45 degrees passes (the exit normal makes 180 - 2 theta with the start normal), under
// CGAL's rule every ray leaves the solid and passes.
float sphere_closed_form(float radius, const SdfOptions& options);

// The estimator's exact value in the middle of a slab of thickness h (far from its rims): every
// ray crosses the thickness at length h / cos(theta) and both false-hit rules accept it.
float slab_closed_form(float thickness, const SdfOptions& options);

// Signed volume enclosed by a triangle mesh (positive when outward-oriented and closed).
double signed_volume(const Mesh& mesh);

// Path of a mesh from CGAL's data set extracted into the build tree ("cow.off").
std::string data_mesh(const std::string& name);

}  // namespace sdfkit::test

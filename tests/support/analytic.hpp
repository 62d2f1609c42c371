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

// Path of a mesh from CGAL's data set extracted into the build tree ("cow.off").
std::string data_mesh(const std::string& name);

}  // namespace sdfkit::test

#pragma once
// Input checks shared by the skeleton's entry points.

#include "sdfkit/core/mesh.hpp"

#include <string>

namespace sdfkit::skeleton::detail {

// Throws InputError unless the mesh is valid (validate_mesh), closed (no boundary edges) and
// edge-manifold: mesh contraction needs a surface that bounds a solid. `what` names the caller.
void require_closed(const Mesh& mesh, const std::string& what);

}  // namespace sdfkit::skeleton::detail

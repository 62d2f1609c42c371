#include "validate.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/topology.hpp"

namespace sdfkit::skeleton::detail {

void require_closed(const Mesh& mesh, const std::string& what) {
  validate_mesh(mesh, what);
  const MeshReport r = analyze(mesh);
  if (r.boundary_edges > 0)
    throw InputError(what + " needs a closed mesh, but this one has " +
                     std::to_string(r.boundary_edges) +
                     " boundary edges (holes); close the holes first");
  if (r.non_manifold_edges > 0)
    throw InputError(what + " needs an edge-manifold mesh, but this one has " +
                     std::to_string(r.non_manifold_edges) + " edges shared by three or more triangles");
}

}  // namespace sdfkit::skeleton::detail

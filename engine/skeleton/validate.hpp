#pragma once
// Input checks shared by the skeleton's entry points, and the repair of closed meshes with
// non-manifold edges.

#include "sdfkit/core/mesh.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace sdfkit::skeleton::detail {

// Throws InputError unless the mesh is valid (validate_mesh), closed (no boundary edges) and
// edge-manifold: mesh contraction needs a surface that bounds a solid. `what` names the caller.
void require_closed(const Mesh& mesh, const std::string& what);

// A closed mesh whose non-manifold edges (three or more triangles) were split.
struct ManifoldSplit {
  bool applied = false;        // false: the mesh had no non-manifold edge (nothing below is set)
  Mesh mesh;                   // the input's vertices first (same indices), then the copies
  std::vector<std::uint32_t> original;  // per vertex of `mesh`: the input vertex it copies
  std::size_t non_manifold_edges = 0;   // in the input
};

// Splits the non-manifold edges of a closed, consistently oriented mesh: around such an edge
// the triangles are paired across the solid wedges they bound (sorted by angle about the edge,
// each triangle is glued to its neighbour on its inner side, which uses the edge the other way
// round), then every vertex gets one copy per fan of triangles glued around it. Parts that only
// touched along an edge (or at a vertex on such an edge) become separate closed surfaces at the
// same place. Throws InputError (the require_closed message) when the pairing does not give a
// closed edge-manifold mesh: open meshes, inconsistent orientation, faces that cross.
ManifoldSplit split_non_manifold(const Mesh& mesh, const std::string& what);

}  // namespace sdfkit::skeleton::detail

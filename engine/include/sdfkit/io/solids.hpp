#pragma once
// The solids of an asset, and which of them share one SDF computation (issue 15).
//
// What the solid is: in a glTF scene each node that draws a mesh is one solid: all of that
// mesh's triangle primitives under the node's world transform, welded together; rays from one
// solid never meet another. A scene of one drawn mesh, and every OBJ, OFF or PLY file, is one
// solid (what `sdfkit compute` has always measured). The SDF is a property of the solid's
// shape, so two instances of a mesh whose world transforms differ by a similarity
// (M_i = s Q M_j, Q orthogonal: rotation, mirror, uniform scale) have the same field up to the
// factor s: it is computed once per (mesh, class) and scaled for the others. Instances through
// a non-similar transform (non-uniform scale, shear) form classes of their own.

#include "sdfkit/io/asset.hpp"

#include <cstdint>
#include <utility>
#include <vector>

namespace sdfkit::io {

struct Solid {
  int node = -1, mesh = -1;  // the glTF node and mesh; -1 for other formats
  // Input vertices [first, first + count) and input triangles of the solid, primitive by
  // primitive (the same sequence of counts for every instance of one mesh).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> vertex_ranges, triangle_ranges;
  int group = 0;       // the solids of one group share one SDF computation
  double scale = 1.0;  // world distances of this solid / those of its group's representative
};

struct SolidPlan {
  std::vector<Solid> solids;                 // scene traversal order
  std::vector<std::size_t> representatives;  // per group, the index of the solid computed
};

// The solids of `asset` and their groups. Two instances of one mesh are grouped when the
// linear parts L of their world transforms satisfy L_i^T L_i = s^2 L_r^T L_r (relative
// tolerance 1e-5 after normalising by the trace), which is exactly L_i = s Q L_r.
SolidPlan plan_solids(const Asset& asset);

}  // namespace sdfkit::io

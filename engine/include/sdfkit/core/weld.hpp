#pragma once
// Welding: input formats split vertices at UV and normal seams; the SDF is computed on positions
// welded together, then mapped back to every input vertex.

#include "sdfkit/core/mesh.hpp"

#include <cstdint>
#include <vector>

namespace sdfkit {

struct WeldResult {
  Mesh mesh;                               // welded positions; triangles in input order
  std::vector<std::uint32_t> input_to_welded;  // one entry per input vertex
};

// Welds positions equal within `tolerance` (model units; 0 = bitwise-equal coordinates, the
// default). With a tolerance, a vertex joins an earlier welded vertex within that
// distance (greedy in input order, so the result is deterministic). Triangle count and order are
// preserved; a triangle whose corners weld together becomes degenerate, not removed.
WeldResult weld(std::span<const glm::vec3> positions, std::span<const Triangle> triangles,
                float tolerance = 0.0f);

}  // namespace sdfkit

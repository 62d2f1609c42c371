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

// The tolerance that welding uses by default: one millionth of the larger of the positions'
// bounding-box diagonal and their largest coordinate magnitude (model units). Seam duplicates
// that were computed twice (a UV sphere's seam and poles, cos(2 pi) next to cos(0)) differ by a
// few float roundings, i.e. a few 1e-7 of the coordinates' magnitude: this merges them with a
// margin, and stays far below any real edge (a 13M-triangle mesh's edges are ~3e-4 of its
// diagonal). 0 for empty or non-finite input.
float default_weld_tolerance(std::span<const glm::vec3> positions);

// Welds positions within `tolerance` of each other (model units; 0 = bitwise-equal coordinates,
// -0 and +0 alike). A vertex joins the earliest earlier welded vertex within that distance
// (greedy in input order, so the result is deterministic and independent of the thread count);
// welded vertices keep the position of their first input vertex and are numbered in input
// order. Triangle count and order are preserved; a triangle whose corners weld together becomes
// degenerate, not removed. Indices out of range are copied as they are.
//
// Found by hashing a grid of cells 16 x the tolerance (a match lies in the cells that the box of
// +-tolerance around a point overlaps: 1 to 8 of them, ~1.4 on average). First, one parallel
// pass enters every vertex in each cell of its box (a table of 32-bit cell tags): when no cell
// is entered twice, no vertex has a candidate, nothing merges, and the result is the input's
// copy with the identity map (8 to 16 bytes per input vertex beside the result). Otherwise an
// open-addressing table of each vertex's own cell is filled and looked up in parallel over the
// hardware threads, and only vertices that have an earlier neighbour within the tolerance are
// then resolved in input order, through bucket chains kept in index order (many copies of one
// point cost linear time); memory beside the result: 16 to 32 bytes per input vertex for that
// table, 12 for hashes and representatives, 8 to 16 more for the chains.
WeldResult weld(std::span<const glm::vec3> positions, std::span<const Triangle> triangles,
                float tolerance = 0.0f);

}  // namespace sdfkit

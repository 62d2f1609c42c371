#pragma once
// Manifold-preserving quadric edge-collapse simplification (Garland & Heckbert 1997), used to
// contract a coarse proxy of a large mesh instead of the mesh itself (see
// ContractionOptions::proxy_vertices).
//
// Each collapse merges the two ends of an edge into one vertex placed at the minimum of the
// sum of their quadrics (area-weighted face-plane quadrics, accumulated over collapses),
// cheapest first; the cost adds the edge length^4 to the quadric error so that the proxy stays
// near uniform where the quadric error is small (flat and straight parts) and every input
// vertex stays near the proxy vertex it went to. A collapse is made only when it keeps the surface a closed 2-manifold of the
// same topology and free of bad triangles:
//   * link condition (Dey et al. 1999): the ends' common neighbours are exactly the two
//     vertices opposite the edge, so no edge becomes non-manifold and no handle closes;
//   * no vertex is left with fewer than three neighbours (no flat two-face pockets, no
//     tetrahedron collapsed into a doubled triangle);
//   * no remaining triangle around the merged vertex turns over (its normal keeps a positive
//     dot product with its old normal, above kMinNormalDot) or becomes degenerate.
// So a closed, edge-manifold input stays closed and edge-manifold with the same number of
// components and the same genus, and no two faces share their three vertices.

#include "sdfkit/core/mesh.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace sdfkit::skeleton::detail {

struct Simplified {
  Mesh mesh;  // the proxy: at most the target's vertices (more only where no collapse is legal)
  // Per input vertex: the proxy vertex it was merged into (input.positions.size() entries,
  // every proxy vertex is the image of at least one input vertex).
  std::vector<std::uint32_t> vertex_map;
  std::size_t collapses = 0;
  std::size_t refused = 0;  // candidate collapses that failed a check above
};

// Simplifies a closed, edge-manifold mesh to at most `target_vertices` vertices (>= 4 per
// component; when no legal collapse is left the result keeps more). Vertices used by no
// triangle are dropped from the proxy and mapped to proxy vertex 0 (none in a validated
// closed mesh). Degenerate input triangles may stay degenerate; no triangle becomes one.
Simplified simplify(const Mesh& mesh, std::size_t target_vertices);

}  // namespace sdfkit::skeleton::detail

#pragma once
// Face orientation: the SDF casts its rays against each point's inward normal, so a face wound
// the wrong way turns its corners' cones outward (and the Vulkan backend's front and back layers
// swap there). Files from scanners, CAD exports and polygon soups often mix windings or come
// inside out. orient_outward makes each piece coherent and outward before anything is computed,
// as MeshLab's "re-orient all faces coherently" and CGAL's orient_to_bound_a_volume do.

#include "sdfkit/core/mesh.hpp"

#include <cstddef>
#include <string>

namespace sdfkit {

struct OrientReport {
  std::size_t flipped_faces = 0;
  std::size_t pieces = 0;              // edge-connected pieces (across edges with exactly two faces)
  std::size_t incoherent_pieces = 0;   // pieces whose faces disagreed across an edge
  std::size_t inverted_pieces = 0;     // coherent closed pieces turned right side out
  std::size_t non_orientable_pieces = 0;  // left as given (a Möbius strip, a Klein bottle)
  // One sentence for a warning; empty when nothing was flipped and every piece is orientable.
  std::string summary() const;
};

// Re-winds faces in place; positions, face count and face order do not change (a flipped face
// (a, b, c) becomes (a, c, b)).
//
// Pieces: faces connected across edges that exactly two faces use (a boundary or non-manifold
// edge separates pieces). Within a piece every face takes the winding of the piece's first face
// relative to its neighbours (breadth first), so each inner edge is used once in each direction.
// Then each piece's sign:
//   - closed (no boundary or non-manifold edge): its signed volume is positive when it bounds a
//     solid, negative when it bounds a cavity. Its nesting depth (how many other closed pieces
//     contain it, by the winding number of a point of its surface) says which it is: even depth
//     is a solid, odd a cavity. A piece whose faces disagreed gets the sign its depth asks for; a
//     coherent piece is turned only when its volume is negative and it lies inside no other
//     piece (inside out: a cavity must be inside something). A coherent piece inside another
//     keeps its winding whatever its sign (a cavity, or a part embedded in another).
//   - open: a piece whose faces disagreed takes the winding the larger area of its faces had;
//     a coherent open piece is kept.
// A piece that cannot be oriented (an edge whose faces must agree and disagree) is left as given.
// Degenerate faces (repeated indices) are left alone and connect nothing. Linear in the faces,
// except the winding numbers: only for closed pieces that need a sign, against the closed pieces
// whose bounding boxes hold their point.
OrientReport orient_outward(Mesh& mesh);

}  // namespace sdfkit

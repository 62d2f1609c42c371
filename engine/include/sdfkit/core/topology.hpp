#pragma once
// Connectivity of a welded mesh: adjacency for the fill and smoothing, and the counts that
// `sdfkit info` reports.

#include "sdfkit/core/mesh.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace sdfkit {

// Compressed adjacency lists: neighbours of i are indices[offsets[i] .. offsets[i+1]).
struct Adjacency {
  std::vector<std::uint32_t> offsets;  // N + 1 entries
  std::vector<std::uint32_t> indices;
  std::size_t size() const { return offsets.empty() ? 0 : offsets.size() - 1; }
};

// Vertex one-ring: vertices sharing an edge of any triangle, no duplicates, sorted. With
// `rings_of` (one flag per vertex), only the flagged vertices' rings are built and the others
// are empty: the SDF's gap filling reads the rings of its gaps only (at 13M triangles the whole
// adjacency is 350 MB at its peak).
Adjacency vertex_adjacency(const Mesh& mesh, std::span<const std::uint8_t> rings_of = {});

// Faces sharing an edge (two common vertices) with each face, sorted.
Adjacency face_adjacency(const Mesh& mesh);

// The faces around each vertex, in face order, one entry per corner (a face that repeats a vertex
// is listed once per repeat). With `skip_degenerate`, faces with a repeated index are left out.
// Indices out of range are not checked (validate_mesh first).
Adjacency vertex_faces(const Mesh& mesh, bool skip_degenerate = false);

struct MeshReport {
  std::size_t vertices = 0;
  std::size_t faces = 0;
  std::size_t components = 0;         // connected by shared vertices, over faces
  std::size_t boundary_edges = 0;     // edges used by exactly one face
  std::size_t non_manifold_edges = 0; // edges used by three or more faces
  std::size_t degenerate_faces = 0;
  std::size_t isolated_vertices = 0;  // used by no face
  Aabb bounds;
};

MeshReport analyze(const Mesh& mesh);

}  // namespace sdfkit

#pragma once
// k-ring Gaussian smoothing of a per-vertex or per-face field on the mesh (the paper's
// post-processing): each point becomes the Gaussian-weighted mean of itself and every point up
// to K edges away (vertex rings, or rings of edge-adjacent faces), weighted by
//     w = exp(-|x_i - x_j|^2 / (2 sigma^2)),
// with sigma = K * (mean edge length) / 2 unless given, so the K-th ring sits near two sigma.

#include "sdfkit/core/mesh.hpp"
#include "sdfkit/core/sdf.hpp"

#include <vector>

namespace sdfkit {

struct SmoothOptions {
  int rings = 2;         // K >= 1
  float sigma = 0.0f;    // model units; 0 = K * mean edge length / 2
  int threads = 0;       // 0 = hardware concurrency
};

// Returns the smoothed values; `values` has one entry per vertex (domain Vertex) or face.
std::vector<float> smooth_field(const Mesh& mesh, SdfDomain domain, std::span<const float> values,
                                const SmoothOptions& options);

// Mean length of the mesh's unique edges (0 for a mesh without edges).
float mean_edge_length(const Mesh& mesh);

}  // namespace sdfkit

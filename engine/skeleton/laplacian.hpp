#pragma once
// The cotangent Laplacian and one-ring areas used by the contraction.

#include "sdfkit/core/mesh.hpp"

#include <Eigen/SparseCore>

#include <vector>

namespace sdfkit::skeleton::detail {

// Degenerate cotangents: each cotangent is clamped to [-kMaxCotangent, kMaxCotangent] (angles
// under ~0.57 degrees or over ~179.4 degrees); a degenerate triangle (triangle_is_degenerate)
// contributes nothing, so a collapsed region keeps only its holding constraint and rests while
// the rest contracts; and an edge weight cot(alpha) + cot(beta) below 0 (a non-Delaunay edge) is
// set to 0. With negative weights L is indefinite and, once W_L is large, the least-squares
// solution can inflate the contracted mesh instead of shrinking it (measured on the
// five-armed star: the total area went from 0.1 back to 2.5 times the initial area); with
// non-negative weights L is a graph Laplacian whose null space is the constants.
inline constexpr double kMaxCotangent = 100.0;

// V by V symmetric cotangent Laplacian: L_ij = max(0, cot(alpha_ij) + cot(beta_ij)) for each edge
// (sum of the cotangents of the angles opposite the edge), L_ii = -sum_j L_ij (Au et al.'s sign
// convention: L V points along the inward mean-curvature normal). Every edge of every triangle
// is stored, also where its weight is 0, so the sparsity pattern depends only on connectivity.
Eigen::SparseMatrix<double> cotangent_laplacian(const Mesh& mesh);

// Per vertex: the sum of the areas of its incident triangles (squared model units).
std::vector<double> one_ring_areas(const Mesh& mesh);

}  // namespace sdfkit::skeleton::detail

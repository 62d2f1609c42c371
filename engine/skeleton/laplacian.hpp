#pragma once
// The cotangent Laplacian and one-ring areas used by the contraction.

#include "sdfkit/core/mesh.hpp"

#include <Eigen/SparseCore>

#include <vector>

namespace sdfkit::skeleton::detail {

// A cotangent is clamped to [-kMaxCotangent, kMaxCotangent] (angles under ~0.57 degrees or
// over ~179.4 degrees), and a degenerate triangle (triangle_is_degenerate) contributes nothing:
// a collapsed region then keeps only its holding constraint, which is what lets it rest while
// the rest of the mesh contracts, and the normal equations stay well conditioned.
inline constexpr double kMaxCotangent = 100.0;

// V by V symmetric cotangent Laplacian: L_ij = cot(alpha_ij) + cot(beta_ij) for each edge
// (sum of the cotangents of the angles opposite the edge), L_ii = -sum_j L_ij (Au et al.'s sign
// convention: L V points along the inward mean-curvature normal). Every edge of every triangle
// is stored, also where its weight is 0, so the sparsity pattern depends only on connectivity.
Eigen::SparseMatrix<double> cotangent_laplacian(const Mesh& mesh);

// Per vertex: the sum of the areas of its incident triangles (squared model units).
std::vector<double> one_ring_areas(const Mesh& mesh);

}  // namespace sdfkit::skeleton::detail

#pragma once
// Intrinsic heat diffusion of a per-vertex field on a triangle mesh: the reference the
// texture-space diffusion and k-ring smoothing are measured against (issue 13, `sdfkit compare
// --diffusion`, tests/diffusion). A Gaussian of sigma (model units) is heat flow for time
// t = sigma² / 2; it is solved as `steps` implicit steps (M + (t / steps) L) u_{k+1} = M u_k with
// L the cotangent Laplacian (positive semi-definite) and M the lumped (barycentric) mass, by a
// sparse Cholesky factorization (Eigen). One step is the resolvent (1 + t Δ)^-1, whose kernel has
// the Gaussian's variance but a sharper peak and heavier tails; more steps converge to heat flow.

#include "sdfkit/core/mesh.hpp"

#include <span>
#include <vector>

namespace sdfkit::diffusion {

// The reference's step count: the one definition that the tests, sdfkit-seam-bench and
// `sdfkit compare --diffusion` use by default. N steps scale a Laplacian mode of eigenvalue λ by
// (1 + tλ/N)^-N instead of heat flow's e^(-tλ); over all λ the two differ by at most 0.20 (N = 1),
// 0.032 (N = 8) and 0.0042 (N = 64), so 64 steps are heat flow to the accuracy the comparisons
// read (bench/RESULTS.md, "Heat reference: 64 steps"). The cost is 64 back-solves of one
// factorization.
inline constexpr int kHeatSteps = 64;

// The lumped (barycentric) mass: per vertex, a third of the area of each triangle around it; 0 for
// a vertex no triangle with area touches. heat_diffusion's M, and the measure whose integral
// texture-space diffusion keeps (conserve_integral).
std::vector<double> lumped_mass(const Mesh& mesh);

// One finite value per vertex, sigma > 0, steps >= 1; throws InputError otherwise. Degenerate
// (zero-area) triangles are skipped; a vertex that no triangle with area touches keeps its value.
std::vector<float> heat_diffusion(const Mesh& mesh, std::span<const float> values, double sigma, int steps = kHeatSteps);

}  // namespace sdfkit::diffusion

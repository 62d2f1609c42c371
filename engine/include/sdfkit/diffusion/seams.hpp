#pragma once
// Seams of a field diffused through an atlas (issue 13's "no seams"): the value jump per unit
// length across mesh edges whose ends belong to different charts (AtlasMapping::vertex_chart),
// against the jump across edges inside charts. A field without seams has a ratio near the one a
// seamless field (heat diffusion) has over the same borders, about 1; the issue asks for ≤ 1.5 at
// the 95th percentile. Used by the tests, `sdfkit-seam-bench` and `sdfkit compare --diffusion`.

#include "sdfkit/core/mesh.hpp"
#include "sdfkit/diffusion/atlas.hpp"

#include <span>
#include <vector>

namespace sdfkit::diffusion {

// Per mesh edge (once), |u_a - u_b| / |x_a - x_b|, split into the edges whose ends belong to
// different charts and the others. Edges of zero length are left out. Throws InputError when
// `values` or the mapping's vertex_chart does not have one entry per vertex.
struct SeamJumps {
  std::vector<double> border, inside;
};
SeamJumps seam_jumps(const Mesh& mesh, const AtlasMapping& mapping, std::span<const float> values);

// The q-quantile (0 ≤ q ≤ 1) of `v`, the element at rank floor(q · (n - 1)); 0 when empty.
double quantile(std::vector<double> v, double q);

// quantile(border, q) / quantile(inside, q); 0 when there is no border edge (one chart) or the
// field is constant inside the charts.
double seam_ratio(const SeamJumps& jumps, double q = 0.95);
double seam_ratio(const Mesh& mesh, const AtlasMapping& mapping, std::span<const float> values, double q = 0.95);

}  // namespace sdfkit::diffusion

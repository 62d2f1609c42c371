// Seam statistics of a field over an atlas's chart partition (seams.hpp).
#include "sdfkit/diffusion/seams.hpp"

#include "sdfkit/core/error.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

namespace sdfkit::diffusion {

SeamJumps seam_jumps(const Mesh& mesh, const AtlasMapping& mapping, std::span<const float> values) {
  const std::size_t V = mesh.vertex_count();
  if (values.size() != V || mapping.vertex_chart.size() != V)
    throw InputError("seam statistics need one value and one chart per vertex (" + std::to_string(V) + "), got " +
                     std::to_string(values.size()) + " and " + std::to_string(mapping.vertex_chart.size()));
  // Each edge once: from its smaller end, in the order of the triangles.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      std::uint32_t p = t[static_cast<std::size_t>(k)], q = t[static_cast<std::size_t>((k + 1) % 3)];
      if (p >= V || q >= V) throw InputError("seam statistics: a triangle index is out of range");
      if (p > q) std::swap(p, q);
      if (p != q) edges.emplace_back(p, q);
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  SeamJumps s;
  for (const auto& [p, q] : edges) {
    const double len = glm::length(glm::dvec3(mesh.positions[p]) - glm::dvec3(mesh.positions[q]));
    if (!(len > 0.0)) continue;
    const double jump = std::abs(static_cast<double>(values[p]) - static_cast<double>(values[q])) / len;
    (mapping.vertex_chart[p] != mapping.vertex_chart[q] ? s.border : s.inside).push_back(jump);
  }
  return s;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

double seam_ratio(const SeamJumps& jumps, double q) {
  if (jumps.border.empty()) return 0.0;
  const double inside = quantile(jumps.inside, q);
  return inside > 0.0 ? quantile(jumps.border, q) / inside : 0.0;
}

double seam_ratio(const Mesh& mesh, const AtlasMapping& mapping, std::span<const float> values, double q) {
  return seam_ratio(seam_jumps(mesh, mapping, values), q);
}

}  // namespace sdfkit::diffusion

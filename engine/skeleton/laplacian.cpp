#include "laplacian.hpp"

#include <glm/geometric.hpp>

#include <algorithm>

namespace sdfkit::skeleton::detail {

Eigen::SparseMatrix<double> cotangent_laplacian(const Mesh& mesh) {
  const auto n = static_cast<Eigen::Index>(mesh.positions.size());
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(mesh.triangles.size() * 6);
  for (const Triangle& t : mesh.triangles) {
    const glm::dvec3 p[3] = {glm::dvec3(mesh.positions[t[0]]), glm::dvec3(mesh.positions[t[1]]),
                             glm::dvec3(mesh.positions[t[2]])};
    const bool degenerate = triangle_is_degenerate(mesh.positions[t[0]], mesh.positions[t[1]],
                                                   mesh.positions[t[2]]);
    for (int k = 0; k < 3; ++k) {
      // Corner k is opposite the edge (i, j).
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      const auto vi = static_cast<Eigen::Index>(t[i]), vj = static_cast<Eigen::Index>(t[j]);
      if (vi == vj) continue;
      double w = 0.0;
      if (!degenerate) {
        const glm::dvec3 a = p[i] - p[k], b = p[j] - p[k];
        const double sine = glm::length(glm::cross(a, b));
        w = std::clamp(glm::dot(a, b) / sine, -kMaxCotangent, kMaxCotangent);
      }
      triplets.emplace_back(vi, vj, w);
      triplets.emplace_back(vj, vi, w);
    }
  }
  Eigen::SparseMatrix<double> L(n, n);
  L.setFromTriplets(triplets.begin(), triplets.end());  // sums the two sides of each edge
  std::vector<double> diagonal(static_cast<std::size_t>(n), 0.0);
  for (Eigen::Index c = 0; c < L.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(L, c); it; ++it) {
      it.valueRef() = std::max(it.value(), 0.0);
      diagonal[static_cast<std::size_t>(c)] += it.value();
    }
  triplets.clear();
  for (Eigen::Index c = 0; c < n; ++c) triplets.emplace_back(c, c, -diagonal[static_cast<std::size_t>(c)]);
  Eigen::SparseMatrix<double> D(n, n);
  D.setFromTriplets(triplets.begin(), triplets.end());
  return L + D;
}

std::vector<double> one_ring_areas(const Mesh& mesh) {
  std::vector<double> area(mesh.positions.size(), 0.0);
  for (const Triangle& t : mesh.triangles) {
    const glm::dvec3 a(mesh.positions[t[0]]), b(mesh.positions[t[1]]), c(mesh.positions[t[2]]);
    const double f = 0.5 * glm::length(glm::cross(b - a, c - a));
    for (std::uint32_t v : t) area[v] += f;
  }
  return area;
}

}  // namespace sdfkit::skeleton::detail

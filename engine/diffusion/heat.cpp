// Intrinsic heat diffusion (heat.hpp): cotangent Laplacian, lumped mass, implicit steps, Eigen.
#include "sdfkit/diffusion/heat.hpp"

#include "sdfkit/core/error.hpp"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <glm/geometric.hpp>

#include <cmath>
#include <string>

namespace sdfkit::diffusion {

std::vector<double> lumped_mass(const Mesh& mesh) {
  std::vector<double> mass(mesh.vertex_count(), 0.0);
  for (const auto& tri : mesh.triangles) {
    const glm::dvec3 p[3] = {glm::dvec3(mesh.positions[tri[0]]), glm::dvec3(mesh.positions[tri[1]]),
                             glm::dvec3(mesh.positions[tri[2]])};
    const double twice_area = glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
    if (!(twice_area > 0.0)) continue;
    for (std::uint32_t v : tri) mass[v] += twice_area / 6.0;
  }
  return mass;
}

std::vector<float> heat_diffusion(const Mesh& mesh, std::span<const float> values, double sigma, int steps) {
  const std::size_t n = mesh.vertex_count();
  if (values.size() != n)
    throw InputError("heat diffusion of " + std::to_string(values.size()) + " values on a mesh of " +
                     std::to_string(n) + " vertices");
  if (!(sigma > 0.0) || !std::isfinite(sigma)) throw InputError("heat diffusion needs a finite sigma > 0");
  if (steps < 1) throw InputError("heat diffusion needs at least one step");
  for (std::size_t v = 0; v < n; ++v)
    if (!std::isfinite(values[v])) throw InputError("vertex " + std::to_string(v) + "'s value is not finite");
  if (n == 0) return {};
  const auto V = static_cast<Eigen::Index>(n);
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(mesh.triangles.size() * 12 + n);
  const std::vector<double> mass = lumped_mass(mesh);
  for (const auto& tri : mesh.triangles) {
    const glm::dvec3 p[3] = {glm::dvec3(mesh.positions[tri[0]]), glm::dvec3(mesh.positions[tri[1]]),
                             glm::dvec3(mesh.positions[tri[2]])};
    const double twice_area = glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
    if (!(twice_area > 0.0)) continue;
    for (std::size_t k = 0; k < 3; ++k) {
      const auto i = static_cast<Eigen::Index>(tri[(k + 1) % 3]), j = static_cast<Eigen::Index>(tri[(k + 2) % 3]);
      const glm::dvec3 a = p[(k + 1) % 3] - p[k], b = p[(k + 2) % 3] - p[k];
      const double w = 0.5 * glm::dot(a, b) / glm::length(glm::cross(a, b));  // half the cotangent at k
      trip.emplace_back(i, j, -w);
      trip.emplace_back(j, i, -w);
      trip.emplace_back(i, i, w);
      trip.emplace_back(j, j, w);
    }
  }
  const double t = 0.5 * sigma * sigma / steps;
  for (auto& e : trip) e = Eigen::Triplet<double>(e.row(), e.col(), t * e.value());
  // A vertex without area keeps its value: a unit diagonal instead of a zero row.
  for (Eigen::Index v = 0; v < V; ++v)
    trip.emplace_back(v, v, mass[static_cast<std::size_t>(v)] > 0.0 ? mass[static_cast<std::size_t>(v)] : 1.0);
  Eigen::SparseMatrix<double> A(V, V);
  A.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(A);
  if (solver.info() != Eigen::Success) throw InputError("heat diffusion: the system could not be factorized");
  Eigen::VectorXd u(V), rhs(V);
  for (Eigen::Index v = 0; v < V; ++v) u[v] = values[static_cast<std::size_t>(v)];
  for (int s = 0; s < steps; ++s) {
    for (Eigen::Index v = 0; v < V; ++v) {
      const double m = mass[static_cast<std::size_t>(v)];
      rhs[v] = (m > 0.0 ? m : 1.0) * u[v];
    }
    u = solver.solve(rhs);
  }
  std::vector<float> out(n);
  for (Eigen::Index v = 0; v < V; ++v) out[static_cast<std::size_t>(v)] = static_cast<float>(u[v]);
  return out;
}

}  // namespace sdfkit::diffusion

#include "sdfkit/post/smooth.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/parallel.hpp"
#include "sdfkit/core/topology.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

namespace sdfkit {

namespace {

// exp(x) for x <= 0 to about 2e-7 relative error: 2^(x log2 e) split into an integer power (built
// in the exponent bits) and 2^f for f in [0, 1) by a degree-6 polynomial. Inlined and branch-light
// so the weighting loop vectorises; underflows to 0 below -87.
inline float exp_nonpositive(float x) {
  x = std::max(x, -87.0f);
  const float t = x * 1.44269504088896341f;
  const float fi = std::floor(t);
  const float f = t - fi;
  float p = 1.53559640e-4f;
  p = p * f + 1.33989500e-3f;
  p = p * f + 9.61817205e-3f;
  p = p * f + 5.55036850e-2f;
  p = p * f + 2.40226510e-1f;
  p = p * f + 6.93147182e-1f;
  p = p * f + 1.0f;
  const std::int32_t bits = (static_cast<std::int32_t>(fi) + 127) << 23;
  float scale;
  std::memcpy(&scale, &bits, sizeof scale);
  return p * scale;
}

// Mean length of the unique edges of a vertex adjacency.
float mean_edge_length(const Mesh& mesh, const Adjacency& adj) {
  double sum = 0.0;
  std::size_t count = 0;
  for (std::uint32_t i = 0; i < adj.size(); ++i)
    for (std::uint32_t k = adj.offsets[i]; k < adj.offsets[i + 1]; ++k) {
      const std::uint32_t j = adj.indices[k];
      if (j <= i) continue;
      sum += glm::length(mesh.positions[i] - mesh.positions[j]);
      ++count;
    }
  return count ? static_cast<float>(sum / static_cast<double>(count)) : 0.0f;
}
}  // namespace

float mean_edge_length(const Mesh& mesh) { return mean_edge_length(mesh, vertex_adjacency(mesh)); }

std::vector<float> smooth_field(const Mesh& mesh, SdfDomain domain, std::span<const float> values,
                                const SmoothOptions& options) {
  if (options.rings < 1 || options.rings > 64)
    throw InputError("--smooth must be between 1 and 64 rings, got " + std::to_string(options.rings));
  const bool per_vertex = domain == SdfDomain::Vertex;
  const std::size_t n = per_vertex ? mesh.positions.size() : mesh.triangles.size();
  if (values.size() != n)
    throw Error("smoothing: " + std::to_string(values.size()) + " values for " + std::to_string(n) +
                (per_vertex ? " vertices" : " faces"));
  const Adjacency vadj = vertex_adjacency(mesh);
  const Adjacency fadj = per_vertex ? Adjacency{} : face_adjacency(mesh);
  const Adjacency& adj = per_vertex ? vadj : fadj;
  const std::vector<glm::vec3> centroids = per_vertex ? std::vector<glm::vec3>{} : face_centroids(mesh);
  const std::vector<glm::vec3>& points = per_vertex ? mesh.positions : centroids;
  float sigma = options.sigma;
  if (!(sigma > 0.0f)) sigma = 0.5f * static_cast<float>(options.rings) * mean_edge_length(mesh, vadj);
  std::vector<float> out(values.begin(), values.end());
  if (!(sigma > 0.0f) || n == 0) return out;
  const float inv_two_sigma2 = 1.0f / (2.0f * sigma * sigma);

  auto work = [&](std::size_t begin, std::size_t end) {
    // Breadth-first rings with a visit stamp per point (no clearing between points); the
    // neighbourhood is collected first and weighted in a second, branch-free loop.
    std::vector<std::uint32_t> stamp(n, UINT32_MAX);
    std::vector<std::uint32_t> hood;
    for (std::size_t i = begin; i < end; ++i) {
      const auto self = static_cast<std::uint32_t>(i);
      stamp[i] = self;
      hood.clear();
      hood.push_back(self);
      std::size_t ring_begin = 0;
      for (int r = 0; r < options.rings; ++r) {
        const std::size_t ring_end = hood.size();
        if (ring_begin == ring_end) break;
        for (std::size_t h = ring_begin; h < ring_end; ++h) {
          const std::uint32_t p = hood[h];
          for (std::uint32_t k = adj.offsets[p]; k < adj.offsets[p + 1]; ++k) {
            const std::uint32_t q = adj.indices[k];
            if (stamp[q] != self) {
              stamp[q] = self;
              hood.push_back(q);
            }
          }
        }
        ring_begin = ring_end;
      }
      const glm::vec3 c = points[i];
      float wsum = 0.0f, vsum = 0.0f;
      for (std::uint32_t q : hood) {
        const glm::vec3 d = points[q] - c;
        const float w = exp_nonpositive(-(d.x * d.x + d.y * d.y + d.z * d.z) * inv_two_sigma2);
        wsum += w;
        vsum += w * values[q];
      }
      out[i] = vsum / wsum;
    }
  };
  parallel_for(n, work, 4096, options.threads > 0 ? static_cast<unsigned>(options.threads) : 0u);
  return out;
}

}  // namespace sdfkit

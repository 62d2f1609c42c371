// Steps 1 and 2: k nearest neighbours (nanoflann k-d tree), PCA normals, and Hoppe's minimum
// spanning tree orientation.

#include "sdfkit/pointcloud/pointcloud.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/parallel.hpp"

#include <Eigen/Dense>
#include <glm/geometric.hpp>
#include <nanoflann.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

namespace sdfkit::pointcloud {
namespace {

struct CloudAdaptor {
  std::span<const glm::vec3> pts;
  std::size_t kdtree_get_point_count() const { return pts.size(); }
  float kdtree_get_pt(std::size_t i, std::size_t d) const { return pts[i][static_cast<int>(d)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const { return false; }
};
using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, CloudAdaptor>,
                                                   CloudAdaptor, 3, std::uint32_t>;

}  // namespace

Neighbours k_nearest(std::span<const glm::vec3> points, int k) {
  if (k < 1) throw InputError("neighbour count must be at least 1 (got " + std::to_string(k) + ")");
  const std::size_t n = points.size();
  Neighbours nb;
  if (n < 2) throw InputError("a point cloud needs at least 2 points for neighbours");
  nb.k = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(k), n - 1));
  const std::size_t kk = static_cast<std::size_t>(nb.k);
  nb.index.resize(n * kk);
  nb.dist2.resize(n * kk);
  CloudAdaptor adaptor{points};
  KdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  parallel_for(n, [&](std::size_t begin, std::size_t end) {
    std::vector<std::uint32_t> idx(kk + 1);
    std::vector<float> d2(kk + 1);
    for (std::size_t i = begin; i < end; ++i) {
      const float q[3] = {points[i].x, points[i].y, points[i].z};
      const std::size_t found = tree.knnSearch(q, kk + 1, idx.data(), d2.data());
      std::size_t out = 0;
      for (std::size_t j = 0; j < found && out < kk; ++j) {
        if (idx[j] == i) continue;  // itself (not always first when points coincide)
        nb.index[i * kk + out] = idx[j];
        nb.dist2[i * kk + out] = d2[j];
        ++out;
      }
    }
  }, 2048);
  return nb;
}

Neighbours first_neighbours(const Neighbours& nb, int k) {
  Neighbours out;
  out.k = std::clamp(k, 1, nb.k);
  const std::size_t n = nb.k > 0 ? nb.index.size() / static_cast<std::size_t>(nb.k) : 0;
  out.index.resize(n * static_cast<std::size_t>(out.k));
  out.dist2.resize(out.index.size());
  for (std::size_t i = 0; i < n; ++i)
    for (int j = 0; j < out.k; ++j) {
      out.index[i * out.k + j] = nb.index[i * nb.k + j];
      out.dist2[i * out.k + j] = nb.dist2[i * nb.k + j];
    }
  return out;
}

std::vector<glm::vec3> pca_normals(std::span<const glm::vec3> points, const Neighbours& nb) {
  const std::size_t n = points.size();
  std::vector<glm::vec3> normals(n);
  parallel_for(n, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const auto ids = nb.of(i);
      glm::dvec3 mean(points[i]);
      for (std::uint32_t j : ids) mean += glm::dvec3(points[j]);
      mean /= static_cast<double>(ids.size() + 1);
      Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
      auto add = [&](const glm::vec3& p) {
        const Eigen::Vector3d d(p.x - mean.x, p.y - mean.y, p.z - mean.z);
        c += d * d.transpose();
      };
      add(points[i]);
      for (std::uint32_t j : ids) add(points[j]);
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
      es.computeDirect(c);
      const Eigen::Vector3d v = es.eigenvectors().col(0);  // smallest eigenvalue first
      glm::vec3 nrm(static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()));
      const float len = glm::length(nrm);
      normals[i] = len > 0.0f && std::isfinite(len) ? nrm / len : glm::vec3(0.0f, 0.0f, 1.0f);
    }
  }, 4096);  // about 0.4 us a point: smaller clouds (the worm) run on one thread, cheaper than a spawn under load
  return normals;
}

Orientation orient_normals_mst(std::span<const glm::vec3> points, std::span<const glm::vec3> normals,
                               const Neighbours& nb, int up_axis) {
  if (up_axis < 0 || up_axis > 2) throw InputError("up axis must be 0 (x), 1 (y) or 2 (z)");
  const std::size_t n = points.size();
  Orientation out;
  out.normals.assign(normals.begin(), normals.end());
  // Symmetric neighbour graph as CSR.
  std::vector<std::uint32_t> degree(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::uint32_t j : nb.of(i)) {
      ++degree[i + 1];
      ++degree[j + 1];
    }
  for (std::size_t i = 0; i < n; ++i) degree[i + 1] += degree[i];
  std::vector<std::uint32_t> adj(degree[n]);
  std::vector<std::uint32_t> fill(degree.begin(), degree.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    for (std::uint32_t j : nb.of(i)) {
      adj[fill[i]++] = j;
      adj[fill[j]++] = static_cast<std::uint32_t>(i);
    }
  // Prim's algorithm over weights 1 - |n_i . n_j|, one tree per connected part.
  std::vector<std::uint8_t> done(n, 0);
  std::vector<float> best(n, std::numeric_limits<float>::infinity());
  std::vector<std::uint32_t> parent(n, std::numeric_limits<std::uint32_t>::max());
  using Item = std::pair<float, std::uint32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> heap;
  std::size_t remaining = n;
  out.components = 0;
  while (remaining > 0) {
    // Seed: the topmost point not yet reached, normal pointing up (out of the bounding box).
    std::uint32_t seed = 0;
    float top = -std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i < n; ++i)
      if (!done[i] && points[i][up_axis] > top) {
        top = points[i][up_axis];
        seed = static_cast<std::uint32_t>(i);
      }
    if (out.components == 0) out.seed = seed;
    ++out.components;
    if (out.normals[seed][up_axis] < 0.0f) out.normals[seed] = -out.normals[seed];
    best[seed] = 0.0f;
    heap.push({0.0f, seed});
    while (!heap.empty()) {
      const auto [w, i] = heap.top();
      heap.pop();
      if (done[i] || w > best[i]) continue;
      done[i] = 1;
      --remaining;
      if (parent[i] != std::numeric_limits<std::uint32_t>::max()) {
        const float d = glm::dot(out.normals[parent[i]], out.normals[i]);
        if (d < 0.0f) out.normals[i] = -out.normals[i];
        if (std::abs(d) < 0.5f) out.ambiguous.push_back(i);
      }
      for (std::uint32_t e = degree[i]; e < degree[i + 1]; ++e) {
        const std::uint32_t j = adj[e];
        if (done[j]) continue;
        const float wj = 1.0f - std::abs(glm::dot(out.normals[i], out.normals[j]));
        if (wj < best[j]) {
          best[j] = wj;
          parent[j] = i;
          heap.push({wj, j});
        }
      }
    }
  }
  std::sort(out.ambiguous.begin(), out.ambiguous.end());
  return out;
}

}  // namespace sdfkit::pointcloud

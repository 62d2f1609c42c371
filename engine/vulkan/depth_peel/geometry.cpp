// Geometry preparation: which triangles are drawn (non-degenerate ones), in which order (by
// normal group on closed meshes in FragmentLists mode), their corners and normals, the framed
// bounding sphere; and their upload.
#include "session.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/topology.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace sdfkit::vk {

// A camera looking along `view` culls a triangle whose normal faces it (dot < 0); it skips a
// whole group (passes::NormalBin), before vertex processing, when every normal in the cone faces
// it by more than kBinMarginDegrees, so the skipped triangles are exactly ones the pipeline would
// cull.
namespace {
constexpr double kBinMarginDegrees = 2.0;
}  // namespace

// Groups unit normals into `bins` cones around spherical Fibonacci axes (nearest axis). Returns
// the groups (empty ones dropped) and fills `order` with the triangles sorted by group.
std::vector<NormalBin> bin_normals(std::span<const glm::vec4> normals, int bins, std::vector<std::uint32_t>& order) {
  std::vector<glm::dvec3> axes(static_cast<std::size_t>(bins));
  for (int i = 0; i < bins; ++i) axes[static_cast<std::size_t>(i)] = fibonacci_sphere_point(i, bins);
  // Draw order: latitude bands, by azimuth within a band, so the groups a camera keeps (a cap
  // of directions) form a few runs, one draw each (about 8 per camera at 128 groups, against
  // 34 in Fibonacci order).
  const int bands = std::max(2, static_cast<int>(std::lround(std::sqrt(bins / 2.0))));
  const auto band_key = [&](const glm::dvec3& a) {
    const int band = std::min(bands - 1, static_cast<int>((1.0 - a.z) / 2.0 * bands));
    return std::pair(band, std::atan2(a.y, a.x));
  };
  std::sort(axes.begin(), axes.end(), [&](const glm::dvec3& a, const glm::dvec3& b) { return band_key(a) < band_key(b); });
  std::vector<std::uint32_t> bin_of(normals.size());
  std::vector<double> min_cos(axes.size(), 1.0);
  std::vector<std::uint32_t> counts(axes.size() + 1, 0);
  for (std::size_t t = 0; t < normals.size(); ++t) {
    const glm::dvec3 n(normals[t]);
    std::size_t best = 0;
    double best_dot = -2.0;
    for (std::size_t b = 0; b < axes.size(); ++b) {
      const double d = glm::dot(axes[b], n);
      if (d > best_dot) {
        best_dot = d;
        best = b;
      }
    }
    bin_of[t] = static_cast<std::uint32_t>(best);
    min_cos[best] = std::min(min_cos[best], best_dot);
    ++counts[best + 1];
  }
  for (std::size_t b = 0; b < axes.size(); ++b) counts[b + 1] += counts[b];
  order.resize(normals.size());
  std::vector<std::uint32_t> next(counts.begin(), counts.end() - 1);
  for (std::size_t t = 0; t < normals.size(); ++t) order[next[bin_of[t]]++] = static_cast<std::uint32_t>(t);
  std::vector<NormalBin> out;
  for (std::size_t b = 0; b < axes.size(); ++b) {
    if (counts[b + 1] == counts[b]) continue;
    NormalBin nb;
    nb.dir = glm::vec3(axes[b]);
    const double spread = std::acos(std::clamp(min_cos[b], -1.0, 1.0)) + kBinMarginDegrees * M_PI / 180.0;
    if (spread < 0.5 * M_PI) nb.skip_below = static_cast<float>(-std::sin(spread));
    nb.first = counts[b];
    nb.count = counts[b + 1] - counts[b];
    out.push_back(nb);
  }
  return out;
}


DepthPeelBackend::Impl::DrawGeometry DepthPeelBackend::Impl::prepare_geometry(
    std::span<const glm::vec3> positions) const {
  DrawGeometry g;
  g.drawn.reserve(triangles.size());
  g.normals.reserve(triangles.size());
  // Degenerate triangles are never drawn (never ray targets); the rest keep their order.
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    const auto& t = triangles[f];
    const glm::vec3 a = positions[t[0]], b = positions[t[1]], c = positions[t[2]];
    if (triangle_is_degenerate(a, b, c)) continue;
    g.drawn.push_back(static_cast<std::uint32_t>(f));
    g.normals.emplace_back(glm::normalize(glm::cross(b - a, c - a)), 0.0f);
  }
  // Closed meshes in FragmentLists mode draw back faces only: draw order by normal group, so a
  // camera can skip the groups facing it. Otherwise the input order.
  if (lists && !front_layers && cfg.normal_bins > 1 && !g.drawn.empty()) {
    std::vector<std::uint32_t> order;
    g.bins = bin_normals(g.normals, cfg.normal_bins, order);
    std::vector<std::uint32_t> sorted_drawn(g.drawn.size());
    std::vector<glm::vec4> sorted_normals(g.normals.size());
    for (std::size_t i = 0; i < order.size(); ++i) {
      sorted_drawn[i] = g.drawn[order[i]];
      sorted_normals[i] = g.normals[order[i]];
    }
    g.drawn = std::move(sorted_drawn);
    g.normals = std::move(sorted_normals);
  }
  g.corners.reserve(3 * g.drawn.size());
  for (std::uint32_t f : g.drawn)
    for (std::uint32_t v : triangles[f]) g.corners.push_back(positions[v]);

  // Bounding sphere: box centre, farthest vertex (only vertices used by triangles count).
  g.center = bounding_box(positions).center();
  float r2 = 0.0f;
  for (const auto& t : triangles)
    for (std::uint32_t v : t) {
      const glm::vec3 d = positions[v] - g.center;
      r2 = std::max(r2, glm::dot(d, d));
    }
  g.radius = std::max(std::sqrt(r2), 1e-20f);
  return g;
}

void DepthPeelBackend::Impl::upload_geometry(const DrawGeometry& geometry) {
  drawn = geometry.drawn;
  bins = geometry.bins;
  center = geometry.center;
  radius = geometry.radius;
  auto upload = [&](Buffer& buf, const void* data, std::size_t bytes, VkBufferUsageFlags usage) {
    const std::size_t alloc = std::max<std::size_t>(bytes, 16);
    if (!buf.buffer || buf.size < alloc) buf = create_buffer(*ctx, alloc, usage, MemoryUse::Upload);
    if (bytes) std::memcpy(buf.mapped(), data, bytes);
  };
  upload(corner_buffer, geometry.corners.data(), geometry.corners.size() * sizeof(glm::vec3),
         VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  upload(normal_buffer, geometry.normals.data(), geometry.normals.size() * sizeof(glm::vec4),
         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
}

}  // namespace sdfkit::vk

#include "bvh.hpp"

#include "sdfkit/core/union_find.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace sdfkit::skeleton::detail {
namespace {

// Möller-Trumbore: distance t along dir to the triangle, or -1 when missed.
float intersect(const glm::vec3& o, const glm::vec3& dir, const glm::vec3& a, const glm::vec3& b,
                const glm::vec3& c) {
  const glm::vec3 e1 = b - a, e2 = c - a;
  const glm::vec3 p = glm::cross(dir, e2);
  const float det = glm::dot(e1, p);
  if (std::abs(det) < 1e-20f) return -1.0f;
  const float inv = 1.0f / det;
  const glm::vec3 s = o - a;
  const float u = glm::dot(s, p) * inv;
  if (u < 0.0f || u > 1.0f) return -1.0f;
  const glm::vec3 q = glm::cross(s, e1);
  const float v = glm::dot(dir, q) * inv;
  if (v < 0.0f || u + v > 1.0f) return -1.0f;
  return glm::dot(e2, q) * inv;
}

// Slab test of the ray against a box; true when [tmin, tmax] overlaps the box.
bool hits_box(const glm::vec3& o, const glm::vec3& inv_dir, const glm::vec3& lo,
              const glm::vec3& hi, float tmin, float tmax) {
  for (int k = 0; k < 3; ++k) {
    float t0 = (lo[k] - o[k]) * inv_dir[k];
    float t1 = (hi[k] - o[k]) * inv_dir[k];
    if (t0 > t1) std::swap(t0, t1);
    // NaN (0 * inf) leaves the bounds unchanged.
    if (t0 > tmin) tmin = t0;
    if (t1 < tmax) tmax = t1;
    if (tmin > tmax) return false;
  }
  return true;
}

}  // namespace

TriangleBvh::TriangleBvh(const Mesh& mesh) : mesh_(&mesh), normals_(face_normals(mesh)) {
  {
    UnionFind parts(mesh.positions.size());
    for (const Triangle& t : mesh.triangles) parts.unite(t[0], t[1]), parts.unite(t[1], t[2]);
    std::vector<std::uint32_t> lowest(mesh.positions.size(), UINT32_MAX);  // per root
    component_.resize(mesh.positions.size());
    for (std::uint32_t k = 0; k < mesh.positions.size(); ++k) {
      std::uint32_t& named = lowest[parts.find(k)];
      if (named == UINT32_MAX) named = k;
      component_[k] = named;
    }
  }
  const auto degenerate = degenerate_faces(mesh);
  std::vector<glm::vec3> centroids = face_centroids(mesh);
  for (std::uint32_t f = 0; f < mesh.triangles.size(); ++f)
    if (!degenerate[f]) order_.push_back(f);
  nodes_.reserve(2 * order_.size() / 4 + 2);
  if (!order_.empty()) build(0, static_cast<std::uint32_t>(order_.size()), centroids);
}

std::uint32_t TriangleBvh::build(std::uint32_t begin, std::uint32_t end,
                                 std::vector<glm::vec3>& centroids) {
  const auto index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back({});
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  glm::vec3 clo = lo, chi = hi;
  for (std::uint32_t i = begin; i < end; ++i) {
    const Triangle& t = mesh_->triangles[order_[i]];
    for (std::uint32_t v : t) {
      lo = glm::min(lo, mesh_->positions[v]);
      hi = glm::max(hi, mesh_->positions[v]);
    }
    clo = glm::min(clo, centroids[order_[i]]);
    chi = glm::max(chi, centroids[order_[i]]);
  }
  if (end - begin <= 4) {
    nodes_[index] = {lo, hi, begin, end - begin};
    return index;
  }
  const glm::vec3 ext = chi - clo;
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  const std::uint32_t mid = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                   [&](std::uint32_t a, std::uint32_t b) { return centroids[a][axis] < centroids[b][axis]; });
  build(begin, mid, centroids);
  const std::uint32_t right = build(mid, end, centroids);
  nodes_[index] = {lo, hi, right, 0};
  return index;
}

template <class Visit>
void TriangleBvh::traverse(const glm::vec3& o, const glm::vec3& dir, float tmin, float& tmax,
                           Visit&& visit) const {
  if (nodes_.empty()) return;
  const glm::vec3 inv_dir(1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z);
  std::uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (!hits_box(o, inv_dir, n.lo, n.hi, tmin, tmax)) continue;
    if (n.count > 0) {
      for (std::uint32_t i = n.first; i < n.first + n.count; ++i)
        if (visit(order_[i])) return;
    } else {
      const auto self = static_cast<std::uint32_t>(&n - nodes_.data());
      stack[top++] = n.first;
      stack[top++] = self + 1;
    }
  }
}

TriangleBvh::Hit TriangleBvh::closest(const glm::vec3& o, const glm::vec3& dir, float tmin,
                                      float tmax, std::uint32_t skip_vertex) const {
  Hit hit;
  traverse(o, dir, tmin, tmax, [&](std::uint32_t f) {
    const Triangle& t = mesh_->triangles[f];
    if (t[0] == skip_vertex || t[1] == skip_vertex || t[2] == skip_vertex) return false;
    const float d = intersect(o, dir, mesh_->positions[t[0]], mesh_->positions[t[1]],
                              mesh_->positions[t[2]]);
    if (d > tmin && d <= tmax) {
      tmax = d;
      hit = {true, d, f};
    }
    return false;
  });
  return hit;
}

bool TriangleBvh::segment_blocked(const glm::vec3& from, const glm::vec3& to, std::uint32_t skip_vertex,
                                  std::uint32_t component) const {
  // The segment is traced from its lexicographically smaller end, so that the answer is a
  // property of the segment, not of the direction asked: a segment that grazes a triangle's
  // edge could be blocked one way and clear the other (boeing, oblong-shuffled: curve edges
  // checked inside as c -> b and counted outside as b -> c).
  const bool swap = to.x != from.x ? to.x < from.x : (to.y != from.y ? to.y < from.y : to.z < from.z);
  const glm::vec3& a = swap ? to : from;
  const glm::vec3& b = swap ? from : to;
  const float len = glm::length(b - a);
  if (!(len > 0.0f)) return false;
  const glm::vec3 dir = (b - a) / len;
  bool blocked = false;
  float tmax = len;
  traverse(a, dir, 0.0f, tmax, [&](std::uint32_t f) {
    const Triangle& t = mesh_->triangles[f];
    if (t[0] == skip_vertex || t[1] == skip_vertex || t[2] == skip_vertex) return false;
    if (component != UINT32_MAX && component_[t[0]] != component) return false;
    const float d = intersect(a, dir, mesh_->positions[t[0]], mesh_->positions[t[1]],
                              mesh_->positions[t[2]]);
    blocked = d > 0.0f && d < len;
    return blocked;
  });
  return blocked;
}

namespace {
const glm::vec3 kSkewDirections[3] = {glm::normalize(glm::vec3(0.5377f, 0.8184f, 0.2026f)),
                                      glm::normalize(glm::vec3(-0.6651f, 0.1939f, -0.7211f)),
                                      glm::normalize(glm::vec3(0.1253f, -0.7731f, 0.6218f))};
}  // namespace

int TriangleBvh::ray_winding(const glm::vec3& p, const glm::vec3& d) const {
  int winding = 0;
  float tmax = std::numeric_limits<float>::max();
  traverse(p, d, 0.0f, tmax, [&](std::uint32_t f) {
    const Triangle& t = mesh_->triangles[f];
    if (intersect(p, d, mesh_->positions[t[0]], mesh_->positions[t[1]], mesh_->positions[t[2]]) > 0.0f)
      winding += glm::dot(normals_[f], d) > 0.0f ? 1 : -1;
    return false;
  });
  return winding;
}

bool TriangleBvh::inside(const glm::vec3& p) const {
  int votes = 0;
  for (const glm::vec3& d : kSkewDirections) votes += ray_winding(p, d) != 0;
  return votes >= 2;
}

bool TriangleBvh::segment_leaves(const glm::vec3& from, const glm::vec3& to) const {
  // From the lexicographically smaller end, as segment_blocked.
  const bool swap = to.x != from.x ? to.x < from.x : (to.y != from.y ? to.y < from.y : to.z < from.z);
  const glm::vec3& a = swap ? to : from;
  const glm::vec3& b = swap ? from : to;
  // The winding number at a along the three rays (inside: 2 of them not 0, as inside()).
  const int votes[3] = {ray_winding(a, kSkewDirections[0]), ray_winding(a, kSkewDirections[1]),
                        ray_winding(a, kSkewDirections[2])};
  if ((votes[0] != 0) + (votes[1] != 0) + (votes[2] != 0) < 2 || !inside(b)) return true;
  const float len = glm::length(b - a);
  if (!(len > 0.0f)) return false;
  const glm::vec3 dir = (b - a) / len;
  // The crossings between the ends, in order, each changing the winding number by one.
  std::vector<std::pair<float, int>> crossings;
  float tmax = len;
  traverse(a, dir, 0.0f, tmax, [&](std::uint32_t f) {
    const Triangle& t = mesh_->triangles[f];
    const float d = intersect(a, dir, mesh_->positions[t[0]], mesh_->positions[t[1]], mesh_->positions[t[2]]);
    if (d > 0.0f && d < len) crossings.push_back({d, glm::dot(normals_[f], dir) > 0.0f ? -1 : 1});
    return false;
  });
  if (crossings.empty()) return false;
  std::sort(crossings.begin(), crossings.end());
  // The winding number at a: the value two of the three rays agree on (a point inside one
  // piece: 1 on every ray).
  int winding = votes[0] == votes[1] || votes[0] == votes[2] ? votes[0] : votes[1] == votes[2] ? votes[1] : 0;
  for (int v : votes) winding = winding == 0 ? v : winding;  // three different values: the first not 0
  for (const auto& [t, step] : crossings) {
    winding += step;
    if (winding == 0) return true;
  }
  return false;
}

}  // namespace sdfkit::skeleton::detail

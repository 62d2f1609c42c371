#include "sdfkit/core/mesh.hpp"
#include "sdfkit/core/parallel.hpp"

#include "sdfkit/core/error.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <string>

namespace sdfkit {

float Aabb::diagonal() const { return glm::length(max - min); }

Aabb bounding_box(std::span<const glm::vec3> positions) {
  Aabb box;
  if (positions.empty()) return box;
  box.min = box.max = positions[0];
  for (const glm::vec3& p : positions) {
    box.min = glm::min(box.min, p);
    box.max = glm::max(box.max, p);
  }
  return box;
}

bool triangle_is_degenerate(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const glm::vec3 e0 = b - a, e1 = c - a, e2 = c - b;
  const float longest2 = std::max({glm::dot(e0, e0), glm::dot(e1, e1), glm::dot(e2, e2)});
  const float twice_area = glm::length(glm::cross(e0, e1));
  // NaN-safe: a NaN area or edge makes the comparison false, so test the accepting form.
  return !(twice_area > kDegenerateRatio * longest2) || !(longest2 > 0.0f);
}

namespace {
bool in_range(const Mesh& mesh, const Triangle& t) {
  const auto n = mesh.positions.size();
  return t[0] < n && t[1] < n && t[2] < n;
}
}  // namespace

std::vector<std::uint8_t> degenerate_faces(const Mesh& mesh) {
  std::vector<std::uint8_t> out(mesh.triangles.size(), 0);
  parallel_for(mesh.triangles.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end; ++f) {
      const Triangle& t = mesh.triangles[f];
      out[f] = !in_range(mesh, t) ||
               triangle_is_degenerate(mesh.positions[t[0]], mesh.positions[t[1]],
                                      mesh.positions[t[2]]);
    }
  }, 1 << 16);
  return out;
}

std::vector<glm::vec3> face_normals(const Mesh& mesh) {
  std::vector<glm::vec3> out(mesh.triangles.size(), glm::vec3(0.0f));
  const auto degenerate = degenerate_faces(mesh);
  parallel_for(mesh.triangles.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end; ++f) {
      if (degenerate[f]) continue;
      const Triangle& t = mesh.triangles[f];
      const glm::vec3& a = mesh.positions[t[0]];
      out[f] = glm::normalize(glm::cross(mesh.positions[t[1]] - a, mesh.positions[t[2]] - a));
    }
  }, 1 << 16);
  return out;
}

std::vector<float> face_areas(const Mesh& mesh) {
  std::vector<float> out(mesh.triangles.size(), 0.0f);
  const auto degenerate = degenerate_faces(mesh);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (degenerate[f]) continue;
    const Triangle& t = mesh.triangles[f];
    const glm::vec3& a = mesh.positions[t[0]];
    out[f] = 0.5f * glm::length(glm::cross(mesh.positions[t[1]] - a, mesh.positions[t[2]] - a));
  }
  return out;
}

namespace {
// Interior angle at corner a of triangle (a, b, c), radians, robust for obtuse angles.
float corner_angle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const glm::vec3 u = b - a, v = c - a;
  return std::atan2(glm::length(glm::cross(u, v)), glm::dot(u, v));
}
}  // namespace

std::vector<glm::vec3> vertex_normals(const Mesh& mesh) {
  // The sums (24 bytes per vertex) in blocks of 2^21 vertices, each freed as soon as its
  // normals are written into the output, whose pages are touched only as it fills: at most one
  // block of the output beside all the sums, not the whole output (6.7M vertices: 176 instead
  // of 228 MiB at once). A block's 48 MiB lie above malloc's largest mmap threshold (32 MiB), so
  // freeing one returns its pages to the system.
  constexpr int kBlockBits = 21;
  const std::size_t nv = mesh.positions.size();
  std::vector<std::vector<glm::dvec3>> sums((nv + (std::size_t{1} << kBlockBits) - 1) >> kBlockBits);
  for (std::size_t b = 0; b < sums.size(); ++b)
    sums[b].assign(std::min(std::size_t{1} << kBlockBits, nv - (b << kBlockBits)), glm::dvec3(0.0));
  const auto sum = [&](std::uint32_t v) -> glm::dvec3& {
    return sums[v >> kBlockBits][v & ((std::uint32_t{1} << kBlockBits) - 1)];
  };
  // The face normals (face_normals' values) and corner angles (the costly part) of a block of
  // faces on all threads, then added in face order on this one: the sums, and so the normals,
  // are those of a sequential loop, without an array of all face normals beside them.
  constexpr std::size_t kBlock = std::size_t{1} << 18;
  std::vector<glm::vec3> normals(std::min(kBlock, mesh.triangles.size()));
  std::vector<std::array<float, 3>> angles(normals.size());
  for (std::size_t first = 0; first < mesh.triangles.size(); first += kBlock) {
    const std::size_t count = std::min(kBlock, mesh.triangles.size() - first);
    parallel_for(count, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const Triangle& t = mesh.triangles[first + i];
        normals[i] = glm::vec3(0.0f);
        if (!in_range(mesh, t)) continue;
        const glm::vec3& a = mesh.positions[t[0]];
        if (triangle_is_degenerate(a, mesh.positions[t[1]], mesh.positions[t[2]])) continue;
        normals[i] = glm::normalize(glm::cross(mesh.positions[t[1]] - a, mesh.positions[t[2]] - a));
        if (normals[i] == glm::vec3(0.0f)) continue;
        for (int k = 0; k < 3; ++k)
          angles[i][static_cast<std::size_t>(k)] = corner_angle(
              mesh.positions[t[k]], mesh.positions[t[(k + 1) % 3]], mesh.positions[t[(k + 2) % 3]]);
      }
    }, 1 << 14);
    for (std::size_t i = 0; i < count; ++i) {
      if (normals[i] == glm::vec3(0.0f)) continue;
      const Triangle& t = mesh.triangles[first + i];
      for (int k = 0; k < 3; ++k)
        sum(t[k]) += glm::dvec3(normals[i]) * static_cast<double>(angles[i][static_cast<std::size_t>(k)]);
    }
  }
  std::vector<glm::vec3> out;
  out.reserve(nv);
  for (std::vector<glm::dvec3>& block : sums) {
    for (const glm::dvec3& s : block) {
      const double len = glm::length(s);
      out.push_back(len > 1e-12 ? glm::vec3(s / len) : glm::vec3(0.0f));
    }
    block = std::vector<glm::dvec3>();
  }
  return out;
}

std::vector<glm::vec3> face_centroids(const Mesh& mesh) {
  std::vector<glm::vec3> out(mesh.triangles.size(), glm::vec3(0.0f));
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const Triangle& t = mesh.triangles[f];
    if (!in_range(mesh, t)) continue;
    out[f] = (mesh.positions[t[0]] + mesh.positions[t[1]] + mesh.positions[t[2]]) / 3.0f;
  }
  return out;
}

namespace {
// The first index in [0, n) where bad(i) holds, or n; on all threads.
template <class Bad>
std::size_t first_bad(std::size_t n, Bad&& bad) {
  std::atomic<std::size_t> first{n};
  parallel_for(n, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i)
      if (bad(i)) {
        std::size_t seen = first.load();
        while (i < seen && !first.compare_exchange_weak(seen, i)) {}
        return;
      }
  }, 1 << 16);
  return first.load();
}
}  // namespace

void validate_mesh(const Mesh& mesh, const std::string& what) {
  if (mesh.triangles.empty()) throw InputError(what + ": the mesh has no triangles");
  const std::size_t v = first_bad(mesh.positions.size(), [&](std::size_t i) {
    const glm::vec3& p = mesh.positions[i];
    return !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z);
  });
  if (v < mesh.positions.size())
    throw InputError(what + ": vertex " + std::to_string(v) +
                     " has a non-finite coordinate (NaN or Inf)");
  const std::size_t f = first_bad(mesh.triangles.size(), [&](std::size_t i) { return !in_range(mesh, mesh.triangles[i]); });
  if (f < mesh.triangles.size())
    throw InputError(what + ": triangle " + std::to_string(f) +
                     " uses a vertex index out of range (" +
                     std::to_string(mesh.positions.size()) + " vertices)");
}

Mesh transformed(const Mesh& mesh, const float (&m)[16]) {
  Mesh out = mesh;
  for (glm::vec3& p : out.positions) {
    const glm::vec3 q = p;
    p = glm::vec3(m[0] * q.x + m[4] * q.y + m[8] * q.z + m[12],
                  m[1] * q.x + m[5] * q.y + m[9] * q.z + m[13],
                  m[2] * q.x + m[6] * q.y + m[10] * q.z + m[14]);
  }
  return out;
}

}  // namespace sdfkit

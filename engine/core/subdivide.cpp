#include "sdfkit/core/mesh.hpp"

#include <algorithm>
#include <unordered_map>

namespace sdfkit {

Mesh subdivide_midpoint(const Mesh& mesh) {
  Mesh out;
  out.positions = mesh.positions;
  out.positions.reserve(mesh.positions.size() + mesh.triangles.size() * 3 / 2 + 16);
  out.triangles.reserve(mesh.triangles.size() * 4);
  std::unordered_map<std::uint64_t, std::uint32_t> midpoints;
  midpoints.reserve(mesh.triangles.size() * 2);
  auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
    const std::uint64_t key = (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
    auto [it, inserted] = midpoints.try_emplace(key, static_cast<std::uint32_t>(out.positions.size()));
    if (inserted) out.positions.push_back(0.5f * (mesh.positions[a] + mesh.positions[b]));
    return it->second;
  };
  for (const Triangle& t : mesh.triangles) {
    const std::uint32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
    out.triangles.push_back({t[0], ab, ca});
    out.triangles.push_back({t[1], bc, ab});
    out.triangles.push_back({t[2], ca, bc});
    out.triangles.push_back({ab, bc, ca});
  }
  return out;
}

}  // namespace sdfkit

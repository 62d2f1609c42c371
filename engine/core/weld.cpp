#include "sdfkit/core/weld.hpp"

#include <glm/geometric.hpp>

#include <cmath>
#include <cstring>
#include <unordered_map>

namespace sdfkit {
namespace {

struct BitsKey {
  std::uint32_t x, y, z;
  bool operator==(const BitsKey&) const = default;
};
struct BitsHash {
  std::size_t operator()(const BitsKey& k) const {
    std::uint64_t h = k.x * 0x9E3779B97F4A7C15ull;
    h ^= (k.y + 0x7F4A7C15ull + (h << 6) + (h >> 2)) * 0xBF58476D1CE4E5B9ull;
    h ^= (k.z + 0x94D049BBull + (h << 6) + (h >> 2)) * 0x94D049BB133111EBull;
    return static_cast<std::size_t>(h ^ (h >> 31));
  }
};

std::uint32_t bits(float f) {
  if (f == 0.0f) f = 0.0f;  // -0 and +0 weld
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

struct CellKey {
  std::int64_t x, y, z;
  bool operator==(const CellKey&) const = default;
};
struct CellHash {
  std::size_t operator()(const CellKey& k) const {
    return static_cast<std::size_t>((k.x * 73856093) ^ (k.y * 19349663) ^ (k.z * 83492791));
  }
};

}  // namespace

WeldResult weld(std::span<const glm::vec3> positions, std::span<const Triangle> triangles,
                float tolerance) {
  WeldResult r;
  r.input_to_welded.resize(positions.size());
  if (tolerance <= 0.0f) {
    std::unordered_map<BitsKey, std::uint32_t, BitsHash> seen;
    seen.reserve(positions.size());
    for (std::size_t i = 0; i < positions.size(); ++i) {
      const glm::vec3& p = positions[i];
      const BitsKey key{bits(p.x), bits(p.y), bits(p.z)};
      auto [it, inserted] = seen.try_emplace(key, static_cast<std::uint32_t>(r.mesh.positions.size()));
      if (inserted) r.mesh.positions.push_back(p);
      r.input_to_welded[i] = it->second;
    }
  } else {
    // Grid of cell size `tolerance`: a match lies in the 27 cells around the point.
    std::unordered_map<CellKey, std::vector<std::uint32_t>, CellHash> grid;
    const double inv = 1.0 / tolerance;
    const float tol2 = tolerance * tolerance;
    for (std::size_t i = 0; i < positions.size(); ++i) {
      const glm::vec3& p = positions[i];
      const CellKey c{static_cast<std::int64_t>(std::floor(p.x * inv)),
                      static_cast<std::int64_t>(std::floor(p.y * inv)),
                      static_cast<std::int64_t>(std::floor(p.z * inv))};
      std::uint32_t match = UINT32_MAX;
      for (int dx = -1; dx <= 1 && match == UINT32_MAX; ++dx)
        for (int dy = -1; dy <= 1 && match == UINT32_MAX; ++dy)
          for (int dz = -1; dz <= 1 && match == UINT32_MAX; ++dz) {
            auto it = grid.find({c.x + dx, c.y + dy, c.z + dz});
            if (it == grid.end()) continue;
            for (std::uint32_t w : it->second) {
              const glm::vec3 d = r.mesh.positions[w] - p;
              if (glm::dot(d, d) <= tol2 && (match == UINT32_MAX || w < match)) match = w;
            }
          }
      if (match == UINT32_MAX) {
        match = static_cast<std::uint32_t>(r.mesh.positions.size());
        r.mesh.positions.push_back(p);
        grid[c].push_back(match);
      }
      r.input_to_welded[i] = match;
    }
  }
  r.mesh.triangles.reserve(triangles.size());
  for (const Triangle& t : triangles) {
    Triangle w = t;
    for (auto& idx : w) idx = idx < positions.size() ? r.input_to_welded[idx] : idx;
    r.mesh.triangles.push_back(w);
  }
  return r;
}

}  // namespace sdfkit

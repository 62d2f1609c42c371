#include "sdfkit/core/shapes.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/weld.hpp"

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include <algorithm>
#include <cmath>
#include <map>

namespace sdfkit::shapes {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Builds strips between consecutive loops of `segments` points. Loops are ordered so that
// u x v points against the direction from one loop to the next (for a profile revolved about
// +z: points counter-clockwise seen from +z, profile traversed from the top down); then every
// triangle faces outward.
struct StripBuilder {
  Mesh mesh;
  int segments;

  std::uint32_t add_point(const glm::vec3& p) {
    mesh.positions.push_back(p);
    return static_cast<std::uint32_t>(mesh.positions.size() - 1);
  }
  std::uint32_t add_loop(const glm::vec3& c, const glm::vec3& u, const glm::vec3& v, float r) {
    const auto first = static_cast<std::uint32_t>(mesh.positions.size());
    for (int i = 0; i < segments; ++i) {
      const double phi = 2.0 * kPi * i / segments;
      mesh.positions.push_back(c + r * (static_cast<float>(std::cos(phi)) * u +
                                        static_cast<float>(std::sin(phi)) * v));
    }
    return first;
  }
  std::uint32_t at(std::uint32_t loop, int i) const {
    return loop + static_cast<std::uint32_t>(i % segments);
  }
  void connect(std::uint32_t a, std::uint32_t b) {
    for (int i = 0; i < segments; ++i) {
      mesh.triangles.push_back({at(a, i), at(b, i), at(b, i + 1)});
      mesh.triangles.push_back({at(a, i), at(b, i + 1), at(a, i + 1)});
    }
  }
  // Fan from a pole to a loop; `first` = the pole comes before the loop in the strip order.
  void fan(std::uint32_t pole, std::uint32_t loop, bool first) {
    for (int i = 0; i < segments; ++i) {
      if (first)
        mesh.triangles.push_back({pole, at(loop, i), at(loop, i + 1)});
      else
        mesh.triangles.push_back({pole, at(loop, i + 1), at(loop, i)});
    }
  }
};

// Revolves a profile (rho, z) about the z axis, top to bottom. Profile ends with rho == 0
// become poles.
Mesh revolve(const std::vector<glm::vec2>& profile, int segments) {
  StripBuilder b{{}, segments};
  const glm::vec3 ux(1, 0, 0), uy(0, 1, 0), uz(0, 0, 1);
  std::uint32_t prev = 0;
  bool prev_is_pole = false;
  for (std::size_t k = 0; k < profile.size(); ++k) {
    const glm::vec2 pr = profile[k];
    const bool pole = pr.x <= 0.0f;
    const std::uint32_t cur = pole ? b.add_point(uz * pr.y) : b.add_loop(uz * pr.y, ux, uy, pr.x);
    if (k > 0) {
      if (prev_is_pole)
        b.fan(prev, cur, true);
      else if (pole)
        b.fan(cur, prev, false);
      else
        b.connect(prev, cur);
    }
    prev = cur;
    prev_is_pole = pole;
  }
  return std::move(b.mesh);
}

void require(bool ok, const char* what) {
  if (!ok) throw InputError(std::string("shape parameters out of range: ") + what);
}

}  // namespace

Mesh sphere(float radius, int segments, int rings) {
  require(radius > 0 && segments >= 3 && rings >= 2, "sphere");
  std::vector<glm::vec2> profile;
  for (int j = 0; j <= rings; ++j) {
    const double t = kPi * j / rings;
    const double rho = (j == 0 || j == rings) ? 0.0 : radius * std::sin(t);
    profile.emplace_back(static_cast<float>(rho), static_cast<float>(radius * std::cos(t)));
  }
  return revolve(profile, segments);
}

Mesh icosphere(float radius, int subdivisions) {
  require(radius > 0 && subdivisions >= 0 && subdivisions <= 8, "icosphere");
  const float t = static_cast<float>((1.0 + std::sqrt(5.0)) / 2.0);
  Mesh m;
  m.positions = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& p : m.positions) p = glm::normalize(p);
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      auto [it, inserted] = mid.try_emplace({key.first, key.second}, 0u);
      if (inserted) {
        m.positions.push_back(glm::normalize(m.positions[a] + m.positions[b]));
        it->second = static_cast<std::uint32_t>(m.positions.size() - 1);
      }
      return it->second;
    };
    std::vector<Triangle> next;
    next.reserve(m.triangles.size() * 4);
    for (const Triangle& tri : m.triangles) {
      const std::uint32_t ab = midpoint(tri[0], tri[1]), bc = midpoint(tri[1], tri[2]),
                          ca = midpoint(tri[2], tri[0]);
      next.push_back({tri[0], ab, ca});
      next.push_back({tri[1], bc, ab});
      next.push_back({tri[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    m.triangles.swap(next);
  }
  for (auto& p : m.positions) p *= radius;
  return m;
}

Mesh capped_cylinder(float radius, float length, int segments, int stacks, int cap_rings) {
  require(radius > 0 && length > 0 && segments >= 3 && stacks >= 1 && cap_rings >= 1,
          "capped_cylinder");
  std::vector<glm::vec2> profile;
  const float h = 0.5f * length;
  for (int k = 0; k < cap_rings; ++k) profile.emplace_back(radius * k / cap_rings, h);
  for (int k = 0; k <= stacks; ++k) profile.emplace_back(radius, h - length * k / stacks);
  for (int k = cap_rings - 1; k >= 0; --k) profile.emplace_back(radius * k / cap_rings, -h);
  return revolve(profile, segments);
}

Mesh open_cylinder(float radius, float height, int segments, int stacks) {
  require(radius > 0 && height > 0 && segments >= 3 && stacks >= 1, "open_cylinder");
  Mesh m;
  m.positions.reserve(static_cast<std::size_t>(segments) * static_cast<std::size_t>(stacks + 1));
  for (int j = 0; j <= stacks; ++j)
    for (int i = 0; i < segments; ++i) {
      const double a = 2.0 * kPi * i / segments;
      m.positions.emplace_back(static_cast<float>(radius * std::cos(a)), static_cast<float>(radius * std::sin(a)),
                               height * static_cast<float>(j) / static_cast<float>(stacks));
    }
  const auto id = [segments](int i, int j) { return static_cast<std::uint32_t>(j * segments + (i % segments)); };
  for (int j = 0; j < stacks; ++j)
    for (int i = 0; i < segments; ++i) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

Mesh capsule(float radius, float length, int segments, int stacks) {
  require(radius > 0 && length >= 0 && segments >= 3 && stacks >= 1, "capsule");
  std::vector<glm::vec2> profile;
  const int cap_steps = std::max(2, segments / 4);
  const float h = 0.5f * length;
  for (int k = 0; k <= cap_steps; ++k) {
    const double a = 0.5 * kPi * k / cap_steps;
    profile.emplace_back(k == 0 ? 0.0f : static_cast<float>(radius * std::sin(a)),
                         static_cast<float>(h + radius * std::cos(a)));
  }
  for (int k = 1; k < stacks; ++k) profile.emplace_back(radius, h - length * k / stacks);
  for (int k = cap_steps; k >= 0; --k) {
    const double a = 0.5 * kPi * k / cap_steps;
    profile.emplace_back(k == 0 ? 0.0f : static_cast<float>(radius * std::sin(a)),
                         static_cast<float>(-h - radius * std::cos(a)));
  }
  return revolve(profile, segments);
}

Mesh torus(float major, float minor, int major_segments, int minor_segments) {
  require(major > minor && minor > 0 && major_segments >= 3 && minor_segments >= 3, "torus");
  StripBuilder b{{}, major_segments};
  const glm::vec3 ux(1, 0, 0), uy(0, 1, 0), uz(0, 0, 1);
  std::vector<std::uint32_t> loops;
  for (int k = 0; k < minor_segments; ++k) {
    // Traverse the tube's circle so that the progression runs downward on the outer side.
    const double psi = -2.0 * kPi * k / minor_segments;
    const float rho = major + minor * static_cast<float>(std::cos(psi));
    loops.push_back(b.add_loop(uz * (minor * static_cast<float>(std::sin(psi))), ux, uy, rho));
  }
  for (int k = 0; k < minor_segments; ++k) b.connect(loops[k], loops[(k + 1) % minor_segments]);
  return std::move(b.mesh);
}

Mesh box(float sx, float sy, float sz, int n) {
  require(sx > 0 && sy > 0 && sz > 0 && n >= 1, "box");
  const float size[3] = {sx, sy, sz};
  // The same integer grid index gives the same float on every face, so edges weld exactly.
  auto coord = [&](int axis, int i) { return size[axis] * (static_cast<float>(i) / n - 0.5f); };
  std::vector<glm::vec3> pos;
  std::vector<Triangle> tris;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      const auto base = static_cast<std::uint32_t>(pos.size());
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j) {
          glm::vec3 p;
          p[a] = side ? 0.5f * size[a] : -0.5f * size[a];
          p[b] = coord(b, i);
          p[c] = coord(c, j);
          pos.push_back(p);
        }
      auto id = [&](int i, int j) { return base + static_cast<std::uint32_t>(i * (n + 1) + j); };
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          // e_b x e_c = e_a: (i,j) -> (i+1,j) -> (i+1,j+1) faces +a.
          if (side) {
            tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
          } else {
            tris.push_back({id(i, j), id(i + 1, j + 1), id(i + 1, j)});
            tris.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
          }
        }
    }
  }
  return weld(pos, tris).mesh;
}

SweptTube swept_tube(float d0, float d1, int rings, int segments) {
  require(d0 > 0 && d1 > 0 && rings >= 2 && segments >= 3, "swept_tube");
  // A gentle planar S curve about 150 units long: its radius of curvature stays well above
  // the largest tube radius (10), so the tube never folds onto itself.
  const glm::dvec3 P[4] = {{0, 0, 0}, {50, 45, 0}, {100, -45, 0}, {150, 0, 0}};
  auto bezier = [&](double t) {
    const double s = 1 - t;
    return s * s * s * P[0] + 3 * s * s * t * P[1] + 3 * s * t * t * P[2] + t * t * t * P[3];
  };
  auto tangent = [&](double t) {
    const double s = 1 - t;
    return glm::normalize(3 * s * s * (P[1] - P[0]) + 6 * s * t * (P[2] - P[1]) +
                          3 * t * t * (P[3] - P[2]));
  };
  // Arc length table.
  const int samples = 8192;
  std::vector<double> arc(samples + 1, 0.0);
  for (int i = 1; i <= samples; ++i)
    arc[i] = arc[i - 1] + glm::length(bezier(double(i) / samples) - bezier(double(i - 1) / samples));
  const double total = arc[samples];
  auto t_at = [&](double s) {
    const auto it = std::lower_bound(arc.begin(), arc.end(), s);
    const auto i = static_cast<int>(std::clamp<std::ptrdiff_t>(it - arc.begin(), 1, samples));
    const double f = (s - arc[i - 1]) / std::max(1e-12, arc[i] - arc[i - 1]);
    return (i - 1 + std::clamp(f, 0.0, 1.0)) / samples;
  };

  SweptTube out;
  StripBuilder b{{}, segments};
  // Rotation-minimising frames by the double reflection method (Wang et al. 2008).
  glm::dvec3 x_prev = bezier(0), t_prev = tangent(0);
  glm::dvec3 r_prev = glm::normalize(glm::cross(t_prev, glm::dvec3(0, 0, 1)));
  std::vector<std::uint32_t> loops;
  std::vector<float> loop_fraction, loop_diameter;
  for (int j = 0; j < rings; ++j) {
    const double frac = double(j) / (rings - 1);
    const double t = t_at(frac * total);
    const glm::dvec3 x = bezier(t), tt = tangent(t);
    glm::dvec3 r = r_prev;
    if (j > 0) {
      const glm::dvec3 v1 = x - x_prev;
      const double c1 = glm::dot(v1, v1);
      const glm::dvec3 rl = r_prev - (2.0 / c1) * glm::dot(v1, r_prev) * v1;
      const glm::dvec3 tl = t_prev - (2.0 / c1) * glm::dot(v1, t_prev) * v1;
      const glm::dvec3 v2 = tt - tl;
      const double c2 = glm::dot(v2, v2);
      r = c2 > 1e-20 ? rl - (2.0 / c2) * glm::dot(v2, rl) * v2 : rl;
      r = glm::normalize(r - glm::dot(r, tt) * tt);
    }
    const glm::dvec3 s = glm::cross(tt, r);  // (r, s, t) right-handed: s x r = -t
    const double diameter = d0 + (d1 - d0) * frac;
    loops.push_back(b.add_loop(glm::vec3(x), glm::vec3(s), glm::vec3(r),
                               static_cast<float>(0.5 * diameter)));
    loop_fraction.push_back(static_cast<float>(frac));
    loop_diameter.push_back(static_cast<float>(diameter));
    x_prev = x;
    t_prev = tt;
    r_prev = r;
  }
  for (int j = 0; j + 1 < rings; ++j) b.connect(loops[j], loops[j + 1]);
  const std::uint32_t c0 = b.add_point(glm::vec3(bezier(0)));
  const std::uint32_t c1 = b.add_point(glm::vec3(bezier(1)));
  b.fan(c0, loops.front(), true);
  b.fan(c1, loops.back(), false);

  out.mesh = std::move(b.mesh);
  const std::size_t nv = out.mesh.positions.size();
  out.true_diameter.resize(nv);
  out.arc_fraction.resize(nv);
  out.on_cap.assign(nv, 0);
  for (int j = 0; j < rings; ++j)
    for (int i = 0; i < segments; ++i) {
      const std::size_t v = loops[j] + static_cast<std::size_t>(i);
      out.true_diameter[v] = loop_diameter[j];
      out.arc_fraction[v] = loop_fraction[j];
      out.on_cap[v] = (j == 0 || j == rings - 1);
    }
  out.true_diameter[c0] = d0;
  out.true_diameter[c1] = d1;
  out.arc_fraction[c0] = 0.0f;
  out.arc_fraction[c1] = 1.0f;
  out.on_cap[c0] = out.on_cap[c1] = 1;
  return out;
}

float sphere_sdf(const glm::vec3& p, float radius) { return glm::length(p) - radius; }

float capped_cylinder_sdf(const glm::vec3& p, float radius, float length) {
  const glm::vec2 d(glm::length(glm::vec2(p.x, p.y)) - radius, std::fabs(p.z) - 0.5f * length);
  return std::min(std::max(d.x, d.y), 0.0f) + glm::length(glm::max(d, glm::vec2(0.0f)));
}

float torus_sdf(const glm::vec3& p, float major, float minor) {
  return glm::length(glm::vec2(glm::length(glm::vec2(p.x, p.y)) - major, p.z)) - minor;
}

float box_sdf(const glm::vec3& p, const glm::vec3& size) {
  const glm::vec3 q = glm::abs(p) - 0.5f * size;
  return glm::length(glm::max(q, glm::vec3(0.0f))) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0f);
}

float capsule_sdf(const glm::vec3& p, float radius, float length) {
  const float h = 0.5f * length;
  const glm::vec3 c(0.0f, 0.0f, std::clamp(p.z, -h, h));
  return glm::length(p - c) - radius;
}

}  // namespace sdfkit::shapes

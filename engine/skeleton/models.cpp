#include "sdfkit/skeleton/models.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/topology.hpp"

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace sdfkit::skeleton::models {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Polynomial smooth minimum (blend width k, model units).
float smooth_min(float a, float b, float k) {
  const float h = std::clamp(0.5f + 0.5f * (b - a) / k, 0.0f, 1.0f);
  return b + (a - b) * h - k * h * (1.0f - h);
}

float segment_distance(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  const float t = len2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return glm::length(p - (a + t * ab));
}

glm::vec3 gradient(const Implicit& fn, const glm::vec3& p, float eps) {
  const glm::vec3 dx(eps, 0, 0), dy(0, eps, 0), dz(0, 0, eps);
  return glm::vec3(fn(p + dx) - fn(p - dx), fn(p + dy) - fn(p - dy), fn(p + dz) - fn(p - dz)) /
         (2.0f * eps);
}

// A triangle of the marching-tetrahedra surface, oriented so its normal points from the
// inside corner(s) toward the outside ones.
void emit(Mesh& mesh, std::uint32_t a, std::uint32_t b, std::uint32_t c, const glm::vec3& outward) {
  const glm::vec3& pa = mesh.positions[a];
  const glm::vec3 nrm = glm::cross(mesh.positions[b] - pa, mesh.positions[c] - pa);
  if (glm::dot(nrm, outward) >= 0.0f)
    mesh.triangles.push_back({a, b, c});
  else
    mesh.triangles.push_back({a, c, b});
}

// The closed surface of the parameter box [0,nu] x [0,nv] x [0,nw] (integer lattice points on
// its boundary), mapped through `map(u, v, w)` with u, v, w in [0, 1]. `map` must preserve
// orientation; triangles face outward.
template <class Map>
Mesh box_surface(int nu, int nv, int nw, Map&& map) {
  Mesh mesh;
  std::unordered_map<long long, std::uint32_t> index;
  auto id = [&](int i, int j, int k) {
    const long long key = (static_cast<long long>(i) * (nv + 1) + j) * (nw + 1) + k;
    auto [it, inserted] = index.try_emplace(key, static_cast<std::uint32_t>(mesh.positions.size()));
    if (inserted)
      mesh.positions.push_back(map(static_cast<float>(i) / nu, static_cast<float>(j) / nv,
                                   static_cast<float>(k) / nw));
    return it->second;
  };
  const int n[3] = {nu, nv, nw};
  for (int axis = 0; axis < 3; ++axis) {
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      for (int s = 0; s < n[a1]; ++s)
        for (int t = 0; t < n[a2]; ++t) {
          std::uint32_t q[4];
          const int ds[4] = {0, 1, 1, 0}, dt[4] = {0, 0, 1, 1};
          for (int c = 0; c < 4; ++c) {
            int g[3];
            g[axis] = side * n[axis];
            g[a1] = s + ds[c];
            g[a2] = t + dt[c];
            q[c] = id(g[0], g[1], g[2]);
          }
          // (a1, a2, axis) is a right-handed cycle, so q0 q1 q2 faces +axis.
          if (side == 1) {
            mesh.triangles.push_back({q[0], q[1], q[2]});
            mesh.triangles.push_back({q[0], q[2], q[3]});
          } else {
            mesh.triangles.push_back({q[0], q[2], q[1]});
            mesh.triangles.push_back({q[0], q[3], q[2]});
          }
        }
    }
  }
  return mesh;
}

// Extrudes a band of `thickness` around the planar polyline `curve` (z = 0) along z.
Plate plate(const std::vector<glm::vec2>& curve, float thickness, float height, float cell) {
  const int nu = static_cast<int>(curve.size()) - 1;
  const int nv = std::max(2, static_cast<int>(std::lround(thickness / cell)));
  const int nw = std::max(2, static_cast<int>(std::lround(height / cell)));
  std::vector<glm::vec2> normal(curve.size());
  for (std::size_t i = 0; i < curve.size(); ++i) {
    const glm::vec2 d = curve[std::min(i + 1, curve.size() - 1)] - curve[i > 0 ? i - 1 : 0];
    normal[i] = glm::normalize(glm::vec2(-d.y, d.x));  // left of the direction of travel
  }
  Plate p;
  p.mesh = box_surface(nu, nv, nw, [&](float u, float v, float w) {
    const auto i = static_cast<std::size_t>(std::lround(u * nu));
    const glm::vec2 xy = curve[i] + (v - 0.5f) * thickness * normal[i];
    return glm::vec3(xy, (w - 0.5f) * height);
  });
  for (const glm::vec2& c : curve) p.centre_curve.emplace_back(c, 0.0f);
  return p;
}

// Points of an arc of `radius` around `centre` from angle a0 to a1 (radians, either sign).
void append_arc(std::vector<glm::vec2>& out, glm::vec2 centre, float radius, double a0, double a1,
                int steps, bool skip_first) {
  for (int i = skip_first ? 1 : 0; i <= steps; ++i) {
    const double a = a0 + (a1 - a0) * i / steps;
    out.push_back(centre + radius * glm::vec2(std::cos(a), std::sin(a)));
  }
}

void require(bool ok, const char* what) {
  if (!ok) throw InputError(std::string("model parameters out of range: ") + what);
}

}  // namespace

Mesh implicit_surface(const Implicit& fn, const Aabb& box, float cell, int relax) {
  require(cell > 0.0f && relax >= 0, "implicit_surface");
  const glm::vec3 ext = box.extent();
  const int nx = std::max(1, static_cast<int>(std::ceil(ext.x / cell)));
  const int ny = std::max(1, static_cast<int>(std::ceil(ext.y / cell)));
  const int nz = std::max(1, static_cast<int>(std::ceil(ext.z / cell)));
  require(static_cast<double>(nx) * ny * nz < 2e7, "implicit_surface grid too fine");
  auto gid = [&](int i, int j, int k) {
    return static_cast<std::int64_t>(i) + static_cast<std::int64_t>(nx + 1) * (j + static_cast<std::int64_t>(ny + 1) * k);
  };
  auto point = [&](int i, int j, int k) { return box.min + cell * glm::vec3(i, j, k); };
  // A grid value that is exactly zero would put a surface vertex on a lattice point shared by
  // many tetrahedra; nudging it outward keeps every crossing on an edge interior.
  const float tiny = 1e-6f * cell;
  std::vector<float> value(static_cast<std::size_t>(gid(nx, ny, nz) + 1));
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        float f = fn(point(i, j, k));
        if (std::abs(f) < tiny) f = tiny;
        value[static_cast<std::size_t>(gid(i, j, k))] = f;
      }

  Mesh mesh;
  std::unordered_map<std::int64_t, std::uint32_t> edge_vertex;
  const std::int64_t stride = gid(nx, ny, nz) + 1;
  auto vertex_on = [&](std::int64_t a, std::int64_t b, const glm::vec3& pa, const glm::vec3& pb) {
    const std::int64_t key = std::min(a, b) * stride + std::max(a, b);
    auto [it, inserted] = edge_vertex.try_emplace(key, static_cast<std::uint32_t>(mesh.positions.size()));
    if (inserted) {
      const float fa = value[static_cast<std::size_t>(a)], fb = value[static_cast<std::size_t>(b)];
      mesh.positions.push_back(pa + (fa / (fa - fb)) * (pb - pa));
    }
    return it->second;
  };
  // The six tetrahedra of a cube (corner bit 1 = +x, 2 = +y, 4 = +z) along the 0-7 diagonal.
  static const int tets[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                 {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        std::int64_t g[8];
        glm::vec3 p[8];
        for (int c = 0; c < 8; ++c) {
          const int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
          g[c] = gid(i + di, j + dj, k + dk);
          p[c] = point(i + di, j + dj, k + dk);
        }
        for (const auto& tet : tets) {
          int in[4], out[4], ni = 0, no = 0;
          for (int c : tet) (value[static_cast<std::size_t>(g[c])] < 0.0f ? in[ni++] : out[no++]) = c;
          if (ni == 0 || no == 0) continue;
          glm::vec3 cin(0.0f), cout(0.0f);
          for (int x = 0; x < ni; ++x) cin += p[in[x]];
          for (int x = 0; x < no; ++x) cout += p[out[x]];
          const glm::vec3 outward = cout / static_cast<float>(no) - cin / static_cast<float>(ni);
          auto v = [&](int a, int b) { return vertex_on(g[a], g[b], p[a], p[b]); };
          if (ni == 1)
            emit(mesh, v(in[0], out[0]), v(in[0], out[1]), v(in[0], out[2]), outward);
          else if (no == 1)
            emit(mesh, v(out[0], in[0]), v(out[0], in[1]), v(out[0], in[2]), outward);
          else {
            const std::uint32_t a = v(in[0], out[0]), b = v(in[0], out[1]), c = v(in[1], out[1]),
                                d = v(in[1], out[0]);
            emit(mesh, a, b, c, outward);
            emit(mesh, a, c, d, outward);
          }
        }
      }

  // Relaxation: umbrella smoothing, then Newton projection back onto the zero set.
  const Adjacency adj = vertex_adjacency(mesh);
  std::vector<glm::vec3> next(mesh.positions.size());
  for (int round = 0; round < relax; ++round) {
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
      glm::vec3 s(0.0f);
      const std::uint32_t b = adj.offsets[v], e = adj.offsets[v + 1];
      for (std::uint32_t x = b; x < e; ++x) s += mesh.positions[adj.indices[x]];
      glm::vec3 q = e > b ? s / static_cast<float>(e - b) : mesh.positions[v];
      for (int step = 0; step < 3; ++step) {
        const glm::vec3 grad = gradient(fn, q, 0.01f * cell);
        const float g2 = glm::dot(grad, grad);
        if (!(g2 > 1e-12f)) break;
        q -= fn(q) * grad / g2;
      }
      next[v] = q;
    }
    mesh.positions.swap(next);
  }
  return mesh;
}

Plate c_shape(float radius, float arc_degrees, float thickness, float height, float cell) {
  require(radius > thickness && arc_degrees > 0 && arc_degrees < 360 && height > 0 && cell > 0,
          "c_shape");
  const double arc = arc_degrees * kPi / 180.0;
  const int steps = std::max(4, static_cast<int>(std::lround(arc * radius / cell)));
  std::vector<glm::vec2> curve;
  // Opening toward +x, symmetric about the x axis.
  append_arc(curve, {0, 0}, radius, kPi - arc / 2.0, kPi + arc / 2.0, steps, false);
  return plate(curve, thickness, height, cell);
}

Plate s_shape(float radius, float arc_degrees, float thickness, float height, float cell) {
  require(radius > thickness && arc_degrees > 0 && arc_degrees < 300 && height > 0 && cell > 0,
          "s_shape");
  const double arc = arc_degrees * kPi / 180.0;
  const int steps = std::max(4, static_cast<int>(std::lround(arc * radius / cell)));
  std::vector<glm::vec2> curve;
  // Upper arc around (0, r) counter-clockwise ending at the origin heading +x, then the lower
  // arc around (0, -r) clockwise from the origin: tangent-continuous, opposite bending.
  append_arc(curve, {0, radius}, radius, 1.5 * kPi - arc, 1.5 * kPi, steps, false);
  append_arc(curve, {0, -radius}, radius, 0.5 * kPi, 0.5 * kPi - arc, steps, true);
  return plate(curve, thickness, height, cell);
}

float distance_to(const std::vector<Segment>& axis, const glm::vec3& p) {
  float best = std::numeric_limits<float>::max();
  for (const Segment& s : axis) best = std::min(best, segment_distance(p, s[0], s[1]));
  return best;
}

Star five_armed_star(std::array<float, 5> radii, float arm_length, float centre_radius, float cell) {
  float largest = 0.0f;
  for (float r : radii) {
    require(r > 0.0f && r < centre_radius, "five_armed_star: arm radius");
    largest = std::max(largest, r);
  }
  require(arm_length > centre_radius && cell > 0.0f, "five_armed_star");
  Star star;
  for (int k = 0; k < 5; ++k) {
    const double a = 2.0 * kPi * k / 5.0;
    star.axis.push_back({glm::vec3(0.0f), arm_length * glm::vec3(std::cos(a), std::sin(a), 0.0)});
  }
  const std::vector<Segment> axis = star.axis;
  const float blend = 0.25f * centre_radius;
  star.fn = [axis, radii, centre_radius, blend](const glm::vec3& p) {
    float d = glm::length(p) - centre_radius;
    for (int k = 0; k < 5; ++k)
      d = smooth_min(d, segment_distance(p, axis[static_cast<std::size_t>(k)][0], axis[static_cast<std::size_t>(k)][1]) - radii[static_cast<std::size_t>(k)], blend);
    return d;
  };
  const float reach = arm_length + largest + 2.0f * cell;
  const float depth = centre_radius + 2.0f * cell;
  star.mesh = implicit_surface(star.fn, {{-reach, -reach, -depth}, {reach, reach, depth}}, cell);
  return star;
}

Genus2 genus2(float major, float minor, float separation, float cell) {
  require(minor > 0 && major > minor && separation > 2.0f * (major - minor) &&
              separation < 2.0f * (major + minor) && cell > 0,
          "genus2 (the tori must overlap without closing a hole)");
  Genus2 g;
  const glm::vec3 c0(-0.5f * separation, 0, 0), c1(0.5f * separation, 0, 0);
  for (const glm::vec3& c : {c0, c1})
    for (int i = 0; i < 64; ++i) {
      const double a0 = 2.0 * kPi * i / 64, a1 = 2.0 * kPi * (i + 1) / 64;
      g.axis.push_back({c + major * glm::vec3(std::cos(a0), std::sin(a0), 0.0),
                        c + major * glm::vec3(std::cos(a1), std::sin(a1), 0.0)});
    }
  const float blend = 0.3f * minor;
  g.fn = [=](const glm::vec3& p) {
    auto torus = [&](const glm::vec3& c) {
      const glm::vec3 q = p - c;
      const float ring = std::sqrt(q.x * q.x + q.y * q.y) - major;
      return std::sqrt(ring * ring + q.z * q.z) - minor;
    };
    return smooth_min(torus(c0), torus(c1), blend);
  };
  const float rx = 0.5f * separation + major + minor + 2.0f * cell;
  const float ry = major + minor + 2.0f * cell, rz = minor + 2.0f * cell;
  g.mesh = implicit_surface(g.fn, {{-rx, -ry, -rz}, {rx, ry, rz}}, cell);
  return g;
}

}  // namespace sdfkit::skeleton::models

#include "analytic.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace sdfkit::test {
namespace {

glm::vec3 gradient(const ImplicitFn& f, const glm::vec3& p, float h) {
  const glm::vec3 dx(h, 0, 0), dy(0, h, 0), dz(0, 0, h);
  const glm::vec3 g(f(p + dx) - f(p - dx), f(p + dy) - f(p - dy), f(p + dz) - f(p - dz));
  const float len = glm::length(g);
  return len > 0.0f ? g / len : glm::vec3(0.0f);
}

// Distance along the ray to the first exit from the solid, or -1 for a miss. Starts inside.
float exit_distance(const ImplicitFn& f, const glm::vec3& o, const glm::vec3& d, float eps,
                    float max_t) {
  float t = 0.0f;
  for (int step = 0; step < 20000; ++step) {
    const float dist = f(o + t * d);
    if (dist > -eps) return t;
    t += -dist;
    if (t > max_t) return -1.0f;
  }
  return -1.0f;
}

}  // namespace

RawSdf analytic_sdf(const SdfQuery& query, const SdfOptions& options, const ImplicitFn& sdf,
                    float scale) {
  const auto rays = cone_rays(options.rays, options.cone_degrees);
  RawSdf raw;
  raw.values.assign(query.size(), 0.0f);
  raw.kept_rays.assign(query.size(), 0u);
  // Converged when within a millionth of the shape size: above float resolution at that size,
  // far below the start offset (1e-5 of the diagonal).
  const float eps = std::min(1e-6f * scale, 0.1f * query.origin_offset);
  std::vector<float> lengths, weights;
  for (std::size_t i = 0; i < query.size(); ++i) {
    if (!query.valid[i]) continue;
    const glm::vec3 n = query.normals[i];
    const Frame frame = tangent_frame(-n);
    const glm::vec3 o = query.origins[i] - query.origin_offset * n;
    lengths.clear();
    weights.clear();
    for (const ConeRay& r : rays) {
      const glm::vec3 d = world_direction(frame, r);
      const float t = exit_distance(sdf, o, d, eps, 4.0f * scale);
      if (t < 0.0f) continue;
      const glm::vec3 hn = gradient(sdf, o + t * d, 1e-4f * scale);
      if (!accept_hit(options.false_hit, n, d, hn)) continue;
      lengths.push_back(t);
      weights.push_back(r.weight);
    }
    const GatherResult g = gather(lengths, weights);
    raw.values[i] = g.value;
    raw.kept_rays[i] = g.kept;
  }
  return raw;
}

float sphere_closed_form(float radius, const SdfOptions& o) {
  std::vector<float> d, w;
  for (const ConeRay& r : cone_rays(o.rays, o.cone_degrees)) {
    if (o.false_hit == FalseHitRule::Paper && r.theta > static_cast<float>(M_PI / 4)) continue;
    d.push_back(2.0f * radius * std::cos(r.theta));
    w.push_back(r.weight);
  }
  return gather(d, w).value;
}

float slab_closed_form(float thickness, const SdfOptions& o) {
  std::vector<float> d, w;
  for (const ConeRay& r : cone_rays(o.rays, o.cone_degrees)) {
    d.push_back(thickness / std::cos(r.theta));
    w.push_back(r.weight);
  }
  return gather(d, w).value;
}

double signed_volume(const Mesh& m) {
  double v = 0;
  for (const Triangle& t : m.triangles)
    v += glm::dot(glm::dvec3(m.positions[t[0]]),
                  glm::cross(glm::dvec3(m.positions[t[1]]), glm::dvec3(m.positions[t[2]]))) / 6.0;
  return v;
}

std::string data_mesh(const std::string& name) { return std::string(SDFKIT_TEST_DATA_DIR) + "/" + name; }

}  // namespace sdfkit::test

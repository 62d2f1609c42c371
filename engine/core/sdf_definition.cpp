#include "sdfkit/core/sdf_definition.hpp"

#include "sdfkit/core/error.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

namespace sdfkit {

std::vector<ConeRay> cone_rays(int ray_count, float cone_degrees) {
  if (ray_count < 1) throw InputError("the ray count must be at least 1");
  if (!(cone_degrees > 0.0f && cone_degrees <= 180.0f))
    throw InputError("the cone angle must be in (0, 180] degrees, got " +
                     std::to_string(cone_degrees));
  const double half = 0.5 * static_cast<double>(cone_degrees) * M_PI / 180.0;
  const double one_minus_cos = 1.0 - std::cos(half);
  std::vector<ConeRay> rays(static_cast<std::size_t>(ray_count));
  for (int i = 0; i < ray_count; ++i) {
    const double cos_t = 1.0 - one_minus_cos * (i + 0.5) / ray_count;
    const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
    const double phi = std::fmod(i * kGoldenAngle, 2.0 * M_PI);
    const double theta = std::acos(std::clamp(cos_t, -1.0, 1.0));
    ConeRay& r = rays[static_cast<std::size_t>(i)];
    r.local_dir = glm::vec3(static_cast<float>(sin_t * std::cos(phi)),
                            static_cast<float>(sin_t * std::sin(phi)), static_cast<float>(cos_t));
    r.theta = static_cast<float>(theta);
    r.weight = sdfkit_ray_weight(r.theta);
  }
  return rays;
}

Frame tangent_frame(const glm::vec3& n) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float b = n.x * n.y * a;
  Frame f;
  f.t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  f.b = glm::vec3(b, sign + n.y * n.y * a, -n.y);
  f.axis = n;
  return f;
}

glm::vec3 world_direction(const Frame& f, const ConeRay& r) {
  return f.t * r.local_dir.x + f.b * r.local_dir.y + f.axis * r.local_dir.z;
}

bool accept_hit(FalseHitRule rule, const glm::vec3& start_normal, const glm::vec3& dir,
                const glm::vec3& hit_normal) {
  return sdfkit_accept_hit(static_cast<std::uint32_t>(rule), start_normal, dir, hit_normal);
}

float cos_half_cone(float cone_degrees) {
  return std::cos(0.5f * cone_degrees * static_cast<float>(M_PI) / 180.0f);
}

bool in_cone(const glm::vec3& inward_normal, const glm::vec3& dir, float cone_degrees) {
  return sdfkit_in_cone(inward_normal, dir, cos_half_cone(cone_degrees));
}

float median_of(std::span<const float> values) {
  if (values.empty()) return 0.0f;
  std::vector<float> sorted(values.begin(), values.end());
  std::sort(sorted.begin(), sorted.end());
  return sorted[sorted.size() / 2];
}

GatherResult gather(std::span<const float> lengths, std::span<const float> weights) {
  GatherResult r;
  const std::size_t k = std::min(lengths.size(), weights.size());
  r.accepted = static_cast<std::uint32_t>(k);
  if (k == 0) return r;

  // Sort indices by length (ties by index) so the order of accumulation is defined.
  std::vector<std::uint32_t> order(k);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return lengths[a] != lengths[b] ? lengths[a] < lengths[b] : a < b;
  });

  const float median = lengths[order[k / 2]];
  float sum = 0.0f;
  for (std::uint32_t i : order) sum += lengths[i];
  const float mean = sum / static_cast<float>(k);
  float var = 0.0f;
  for (std::uint32_t i : order) {
    const float d = lengths[i] - mean;
    var += d * d;
  }
  const float sigma = std::sqrt(var / static_cast<float>(k));

  float wsum = 0.0f, wdsum = 0.0f;
  for (std::uint32_t i : order) {
    if (std::fabs(lengths[i] - median) <= sigma) {
      wsum += weights[i];
      wdsum += weights[i] * lengths[i];
      ++r.kept;
    }
  }
  // The median itself always passes (|m - m| = 0 <= sigma), so kept >= 1 and wsum > 0.
  r.value = wdsum / wsum;
  return r;
}

}  // namespace sdfkit

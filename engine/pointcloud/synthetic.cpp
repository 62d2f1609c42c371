// Synthetic worms: a closed tube of varying radius around a known planar curve, sampled as a
// noisy point cloud, with its exact midline.

#include "sdfkit/pointcloud/pointcloud.hpp"

#include "sdfkit/core/error.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace sdfkit::pointcloud {
namespace {

// The axis as a dense table: a sine wave z = A sin(2 pi waves x / X + phase) over x in [0, X],
// with X chosen so that the arc length is `length`.
struct Axis {
  std::vector<glm::vec3> p;  // dense samples
  std::vector<float> s;      // arc length at each sample
};

Axis make_axis(const WormShape& w) {
  constexpr int kSamples = 4000;
  auto build = [&](double X) {
    Axis a;
    a.p.resize(kSamples + 1);
    a.s.resize(kSamples + 1);
    for (int i = 0; i <= kSamples; ++i) {
      const double x = X * i / kSamples;
      const double z = w.wave_amplitude * std::sin(2.0 * std::numbers::pi * w.waves * x / X + w.phase);
      a.p[i] = glm::vec3(static_cast<float>(x), 0.0f, static_cast<float>(z));
      a.s[i] = i == 0 ? 0.0f : a.s[i - 1] + glm::distance(a.p[i - 1], a.p[i]);
    }
    return a;
  };
  double lo = 1e-3 * w.length, hi = w.length;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (build(mid).s.back() > w.length ? hi : lo) = mid;
  }
  return build(hi);
}

// Position and frame on the axis at arc length s.
void axis_at(const Axis& a, float s, glm::vec3& pos, glm::vec3& tangent) {
  std::size_t i = static_cast<std::size_t>(std::lower_bound(a.s.begin(), a.s.end(), s) - a.s.begin());
  i = std::clamp<std::size_t>(i, 1, a.s.size() - 1);
  const float len = a.s[i] - a.s[i - 1];
  const float u = len > 0.0f ? std::clamp((s - a.s[i - 1]) / len, 0.0f, 1.0f) : 0.0f;
  pos = glm::mix(a.p[i - 1], a.p[i], u);
  tangent = glm::normalize(a.p[i] - a.p[i - 1]);
}

float radius_at(const WormShape& w, float s) {
  const float x = std::abs(2.0f * s / w.length - 1.0f);  // 0 mid-body, 1 at the tips
  return w.max_radius * std::sqrt(std::max(0.0f, 1.0f - std::pow(x, 4.0f)));
}

}  // namespace

SyntheticWorm synthetic_worm(const WormShape& w) {
  if (!(w.length > 0.0f) || !(w.max_radius > 0.0f) || w.points < 16 || !(w.noise >= 0.0f))
    throw InputError("synthetic worm: length, radius and noise must be positive and points >= 16");
  const Axis axis = make_axis(w);
  SyntheticWorm worm;
  worm.length = w.length;
  std::mt19937 rng(w.seed);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  std::normal_distribution<float> gauss(0.0f, 1.0f);
  worm.points.reserve(w.points);
  const glm::vec3 up(0.0f, 1.0f, 0.0f);
  while (worm.points.size() < w.points) {
    // Area-uniform: s with density proportional to the local circumference (rejection), plus
    // the tips' caps, where the radius changes fast along s, sampled by their slope.
    const float s = uni(rng) * w.length;
    const float r = radius_at(w, s);
    const float ds = 1e-3f * w.length;
    const float dr = (radius_at(w, std::min(w.length, s + ds)) - radius_at(w, std::max(0.0f, s - ds))) / (2.0f * ds);
    const float weight = r * std::sqrt(1.0f + dr * dr);
    if (uni(rng) * w.max_radius * 4.0f > weight) continue;
    glm::vec3 c, t;
    axis_at(axis, s, c, t);
    const glm::vec3 n = glm::normalize(glm::cross(up, t));
    const float theta = 2.0f * std::numbers::pi_v<float> * uni(rng);
    const glm::vec3 dir = std::cos(theta) * n + std::sin(theta) * up;
    worm.points.push_back(c + (r + w.noise * gauss(rng)) * dir);
  }
  constexpr int kNodes = 201;
  worm.midline.nodes.resize(kNodes);
  for (int i = 0; i < kNodes; ++i) {
    const float s = w.length * static_cast<float>(i) / (kNodes - 1);
    glm::vec3 c, t;
    axis_at(axis, s, c, t);
    worm.midline.nodes[i] = {c, radius_at(w, s)};
  }
  return worm;
}

}  // namespace sdfkit::pointcloud

#pragma once
// Cases for holding a device's false-hit rules and cone test (sdf_definition_shared.h) to the
// C++ definition: three vec4 per case, the start point's outward normal (w = the cosine of the
// cone's half-angle), the ray or view direction, the hit's outward normal. Random unit vectors
// plus the boundaries: dot products of exactly 0 and -0 (where Paper keeps and Cgal drops), a
// direction exactly on the cone's boundary (inside), a hair outside it.

#include "sdfkit/core/sdf_definition.hpp"

#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <random>
#include <vector>

namespace sdfkit::test {

inline std::vector<glm::vec4> definition_cases(int random_cases = 2000) {
  std::vector<glm::vec4> c;
  const auto add = [&](glm::vec3 start, float cos_half, glm::vec3 dir, glm::vec3 hit) {
    c.emplace_back(start, cos_half);
    c.emplace_back(dir, 0.0f);
    c.emplace_back(hit, 0.0f);
  };
  const float cos60 = 0.5f;
  add({0, 0, 1}, cos60, {0, 0, -1}, {1, 0, 0});     // hit . start = 0: Paper keeps; dir . hit = 0: Cgal drops
  add({0, 0, 1}, cos60, {0, 0, -1}, {-0.0f, 0, -0.0f});
  add({0, 0, 1}, cos60, {0, 0, -1}, {0, 0, -1});    // the opposite wall: both keep
  add({0, 0, 1}, cos60, {0, 0, -1}, {0, 0, 1});     // a wall facing back: both drop
  add({0, 0, 1}, 0.6f, {0, 0.8f, -0.6f}, {0, 0, -1});  // dot(inward, dir) = 0.6 exactly: in the cone
  add({0, 0, 1}, std::nextafter(0.6f, 1.0f), {0, 0.8f, -0.6f}, {0, 0, -1});  // a hair outside
  add({1, 0, 0}, 1.0f, {-1, 0, 0}, {1, 0, 0});      // the axis itself at aperture 0
  add({1, 0, 0}, -1.0f, {1, 0, 0}, {-1, 0, 0});     // aperture 360: everything
  std::mt19937 rng(5);
  std::normal_distribution<float> g;
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const auto unit = [&] { return glm::normalize(glm::vec3(g(rng), g(rng), g(rng))); };
  for (int i = 0; i < random_cases; ++i) add(unit(), u(rng), unit(), unit());
  return c;
}

// The C++ definition's answer for case i: bit 0 Paper keeps, bit 1 Cgal keeps, bit 2 in cone.
inline std::uint32_t definition_bits(const std::vector<glm::vec4>& cases, std::size_t i) {
  const glm::vec3 start(cases[3 * i]), dir(cases[3 * i + 1]), hit(cases[3 * i + 2]);
  std::uint32_t b = 0;
  if (accept_hit(FalseHitRule::Paper, start, dir, hit)) b |= 1u;
  if (accept_hit(FalseHitRule::Cgal, start, dir, hit)) b |= 2u;
  if (sdfkit_in_cone(-start, dir, cases[3 * i].w)) b |= 4u;
  return b;
}

}  // namespace sdfkit::test

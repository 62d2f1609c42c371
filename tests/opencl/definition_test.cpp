// The device's versions of the shared definition, held to the C++ one: the generated rays and
// their weights, and the gather (median, sigma filter, weighted mean).
#include "definition_cases.hpp"
#include "device_fixture.hpp"

#include "sdfkit/core/sdf_definition.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <random>

using namespace sdfkit;

TEST(OpenClDefinition, DeviceRaysMatchConeRaysAndWorldDirection) {
  SDFKIT_REQUIRE_CL(backend);
  std::mt19937 rng(7);
  std::normal_distribution<float> g;
  std::vector<glm::vec3> normals = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {0, -1, 0}, {0, 0, -0.0f}};
  normals[4] = glm::normalize(glm::vec3(1e-3f, 0, -0.0f));
  for (int i = 0; i < 200; ++i) normals.push_back(glm::normalize(glm::vec3(g(rng), g(rng), g(rng))));
  for (const auto& [rays, cone] : {std::pair{30, 120.0f}, {25, 120.0f}, {1, 60.0f}, {1024, 180.0f}, {7, 10.0f}}) {
    SdfOptions o;
    o.rays = rays;
    o.cone_degrees = cone;
    const auto expected = cone_rays(rays, cone);
    const std::vector<glm::vec4> got = backend.ray_directions_for_test(normals, o);
    ASSERT_EQ(got.size(), normals.size() * static_cast<std::size_t>(rays));
    float worst = 0.0f, worst_w = 0.0f;
    for (std::size_t p = 0; p < normals.size(); ++p) {
      const Frame f = tangent_frame(-normals[p]);
      for (int r = 0; r < rays; ++r) {
        const glm::vec4 d = got[p * static_cast<std::size_t>(rays) + static_cast<std::size_t>(r)];
        const glm::vec3 want = world_direction(f, expected[static_cast<std::size_t>(r)]);
        worst = std::max(worst, glm::length(glm::vec3(d) - want));
        worst_w = std::max(worst_w, std::fabs(d.w - expected[static_cast<std::size_t>(r)].weight) /
                                        expected[static_cast<std::size_t>(r)].weight);
      }
    }
    // Float rounding of the trigonometry: a few ulps of a unit vector.
    EXPECT_LT(worst, 2e-6f) << rays << " rays, " << cone << " degrees";
    EXPECT_LT(worst_w, 2e-6f) << rays << " rays, " << cone << " degrees";
  }
}

TEST(OpenClDefinition, DeviceGatherEqualsTheDefinition) {
  SDFKIT_REQUIRE_CL(backend);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> len(0.1f, 10.0f), u(0.0f, 1.0f);
  for (const int rays : {30, 25, 1, 2, 64}) {
    const auto cone = cone_rays(rays, 120.0f);
    std::vector<float> weights;
    for (const ConeRay& r : cone) weights.push_back(r.weight);
    const int points = 400;
    std::vector<float> lengths(static_cast<std::size_t>(points * rays));
    for (int p = 0; p < points; ++p) {
      const float drop = p % 10 == 0 ? 1.0f : 0.3f * u(rng);  // some points have no hit at all
      const float base = len(rng);
      for (int r = 0; r < rays; ++r) {
        float v = base * (0.5f + u(rng)) + (u(rng) < 0.1f ? 5.0f * base : 0.0f);  // outliers
        if (p % 7 == 3) v = base * (u(rng) < 0.5f ? 1.0f : 2.0f);  // many exact ties
        lengths[static_cast<std::size_t>(p * rays + r)] = u(rng) < drop ? -1.0f : v;
      }
    }
    const RawSdf got = backend.gather_lengths_for_test(lengths, weights, rays);
    ASSERT_EQ(got.values.size(), static_cast<std::size_t>(points));
    for (int p = 0; p < points; ++p) {
      std::vector<float> l, w;
      for (int r = 0; r < rays; ++r) {
        const float v = lengths[static_cast<std::size_t>(p * rays + r)];
        if (v < 0.0f) continue;
        l.push_back(v);
        w.push_back(weights[static_cast<std::size_t>(r)]);
      }
      const GatherResult want = gather(l, w);
      EXPECT_EQ(got.kept_rays[static_cast<std::size_t>(p)], want.kept) << "point " << p;
      // Same operations in the same order in float: equal up to the last bit or two.
      EXPECT_FLOAT_EQ(got.values[static_cast<std::size_t>(p)], want.value) << "point " << p;
    }
  }
}

TEST(OpenClDefinition, FalseHitRulesAndConeTestEqualTheDefinition) {
  SDFKIT_REQUIRE_CL(backend);
  const std::vector<glm::vec4> cases = test::definition_cases();
  const std::vector<std::uint32_t> got = backend.definition_probe_for_test(cases);
  ASSERT_EQ(got.size(), cases.size() / 3);
  std::uint32_t seen = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    const std::uint32_t want = test::definition_bits(cases, i);
    seen |= (want & 3u) == 1u ? 1u : (want & 3u) == 2u ? 2u : 0u;
    ASSERT_EQ(got[i], want) << "case " << i;
  }
  EXPECT_EQ(seen, 3u) << "the cases must include hits only one rule keeps, each way";
}

#include "sdfkit/core/sdf_definition.hpp"

#include "sdfkit/core/error.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace sdfkit;

TEST(ConeRays, FollowTheSphericalFibonacciFormula) {
  const int n = 30;
  const auto rays = cone_rays(n, 120.0f);
  ASSERT_EQ(rays.size(), 30u);
  const double one_minus_cos = 1.0 - std::cos(M_PI / 3.0);
  for (int i = 0; i < n; ++i) {
    const double cos_t = 1.0 - one_minus_cos * (i + 0.5) / n;
    EXPECT_NEAR(rays[i].local_dir.z, cos_t, 1e-6);
    EXPECT_NEAR(glm::length(rays[i].local_dir), 1.0, 1e-6);
    EXPECT_NEAR(rays[i].theta, std::acos(cos_t), 1e-6);
    EXPECT_NEAR(rays[i].weight, 1.0 / std::acos(cos_t), 1e-4);
    const double phi = std::atan2(rays[i].local_dir.y, rays[i].local_dir.x);
    const double expected_phi = std::remainder(i * kGoldenAngle, 2 * M_PI);
    EXPECT_NEAR(std::remainder(phi - expected_phi, 2 * M_PI), 0.0, 1e-5) << i;
  }
}

TEST(ConeRays, StayInsideTheCone) {
  for (float cone : {10.0f, 60.0f, 120.0f, 180.0f}) {
    for (const ConeRay& r : cone_rays(50, cone)) {
      EXPECT_LE(r.theta, (cone * float(M_PI) / 180.0f) * 0.5f + 1e-6f);
      EXPECT_GT(r.theta, 0.0f);
    }
  }
}

TEST(ConeRays, RejectBadArguments) {
  EXPECT_THROW(cone_rays(0, 120.0f), InputError);
  EXPECT_THROW(cone_rays(30, 0.0f), InputError);
  EXPECT_THROW(cone_rays(30, 181.0f), InputError);
  EXPECT_THROW(cone_rays(30, std::nanf("")), InputError);
}

TEST(TangentFrame, IsOrthonormalAndRightHanded) {
  std::mt19937 rng(7);
  std::normal_distribution<float> g;
  for (int k = 0; k < 1000; ++k) {
    glm::vec3 n = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
    if (k == 0) n = glm::vec3(0, 0, -1);
    if (k == 1) n = glm::vec3(0, 0, 1);
    const Frame f = tangent_frame(n);
    EXPECT_NEAR(glm::length(f.t), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::length(f.b), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(f.t, f.b), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(f.t, n), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(f.b, n), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(glm::cross(f.t, f.b), n), 1.0f, 1e-5f);
  }
}

TEST(WorldDirection, KeepsTheAngleToTheAxis) {
  const glm::vec3 axis = glm::normalize(glm::vec3(0.3f, -0.4f, 0.5f));
  const Frame f = tangent_frame(axis);
  for (const ConeRay& r : cone_rays(30, 120.0f))
    EXPECT_NEAR(std::acos(glm::dot(world_direction(f, r), axis)), r.theta, 1e-3);
}

TEST(AcceptHit, PaperAndCgalRules) {
  const glm::vec3 n(0, 0, 1), d(0, 0, -1);
  // Opposite wall of a slab: accepted by both rules.
  EXPECT_TRUE(accept_hit(FalseHitRule::Paper, n, d, glm::vec3(0, 0, -1)));
  EXPECT_TRUE(accept_hit(FalseHitRule::Cgal, n, d, glm::vec3(0, 0, -1)));
  // A surface facing the same way as the start (entering another part): dropped by both.
  EXPECT_FALSE(accept_hit(FalseHitRule::Paper, n, d, glm::vec3(0, 0, 1)));
  EXPECT_FALSE(accept_hit(FalseHitRule::Cgal, n, d, glm::vec3(0, 0, 1)));
  // A side wall at 60 degrees to n, which the ray leaves through: the rules disagree.
  const glm::vec3 dir = glm::normalize(glm::vec3(1, 0, -1));
  const glm::vec3 hit = glm::normalize(glm::vec3(1, 0, 0.5f));
  EXPECT_FALSE(accept_hit(FalseHitRule::Paper, n, dir, hit));
  EXPECT_TRUE(accept_hit(FalseHitRule::Cgal, n, dir, hit));
}

TEST(Median, IsTheElementAtHalfTheCountOfTheSortedValues) {
  const float odd[] = {5, 1, 3};
  EXPECT_EQ(median_of(odd), 3.0f);
  const float even[] = {4, 1, 3, 2};  // sorted 1 2 3 4, index 2
  EXPECT_EQ(median_of(even), 3.0f);
  EXPECT_EQ(median_of(std::span<const float>{}), 0.0f);
}

TEST(Gather, HandComputedExample) {
  // lengths 1, 2, 3, 10: median = sorted[2] = 3, mean 4, sigma = sqrt((9+4+1+36)/4) = 3.5355.
  // Kept: |1-3|=2, |2-3|=1, |3-3|=0 (<= 3.54); 10 dropped.
  const float d[] = {10, 2, 1, 3};
  const float w[] = {1, 2, 4, 8};
  const GatherResult g = gather(d, w);
  EXPECT_EQ(g.accepted, 4u);
  EXPECT_EQ(g.kept, 3u);
  EXPECT_NEAR(g.value, (2 * 2 + 4 * 1 + 8 * 3) / 14.0, 1e-6);
}

TEST(Gather, EqualLengthsAreAllKept) {
  const float d[] = {2, 2, 2};
  const float w[] = {1, 5, 9};
  const GatherResult g = gather(d, w);
  EXPECT_EQ(g.kept, 3u);
  EXPECT_FLOAT_EQ(g.value, 2.0f);
}

TEST(Gather, EmptyInputHasNoValue) {
  const GatherResult g = gather({}, {});
  EXPECT_EQ(g.kept, 0u);
  EXPECT_EQ(g.value, 0.0f);
}

TEST(Gather, ValueLiesWithinTheKeptRangeForRandomInput) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.1f, 10.0f);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<float> d(1 + trial % 40), w(d.size());
    for (auto& x : d) x = u(rng);
    for (auto& x : w) x = u(rng);
    const GatherResult g = gather(d, w);
    ASSERT_GE(g.kept, 1u);
    const float m = median_of(d);
    float lo = 1e30f, hi = -1e30f;
    double mean = 0, var = 0;
    for (float x : d) mean += x;
    mean /= d.size();
    for (float x : d) var += (x - mean) * (x - mean);
    const double sigma = std::sqrt(var / d.size());
    for (float x : d)
      if (std::fabs(x - m) <= sigma + 1e-5) {
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
    EXPECT_GE(g.value, lo - 1e-4f);
    EXPECT_LE(g.value, hi + 1e-4f);
    EXPECT_TRUE(std::isfinite(g.value));
  }
}

TEST(InCone, DirectionsOnTheBoundaryAreInside) {
  // cos(60 degrees) rounds to 0.49999997f in float: a direction at exactly 0.5 is inside, one
  // at a cosine a hair below the rounded value is outside.
  EXPECT_FLOAT_EQ(cos_half_cone(120.0f), 0.5f);
  const glm::vec3 axis(0, 0, 1);
  EXPECT_TRUE(in_cone(axis, glm::vec3(std::sqrt(0.75f), 0.0f, 0.5f), 120.0f));
  EXPECT_TRUE(in_cone(axis, axis, 1.0f));
  EXPECT_FALSE(in_cone(axis, glm::vec3(1, 0, 0), 120.0f));
  EXPECT_TRUE(in_cone(axis, glm::vec3(0, 0, -1), 360.0f));  // cos(180) = -1: everything
  EXPECT_EQ(sdfkit_ray_weight(0.0f), 1.0f / kMinRayAngle);
  EXPECT_EQ(sdfkit_ray_weight(0.5f), 2.0f);
}

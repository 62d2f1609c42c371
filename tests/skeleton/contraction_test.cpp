// Internals of the skeleton library held to independent computations: the BVH against brute
// force, the cotangent Laplacian against its definition.

#include "bvh.hpp"
#include "laplacian.hpp"

#include "sdfkit/core/shapes.hpp"
#include "sdfkit/skeleton/models.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <limits>
#include <random>

using namespace sdfkit;
namespace detail = sdfkit::skeleton::detail;

namespace {

// Brute-force closest hit along a ray (Möller-Trumbore in double).
float brute_closest(const Mesh& m, const glm::vec3& o, const glm::vec3& d) {
  double best = std::numeric_limits<double>::infinity();
  for (const Triangle& t : m.triangles) {
    const glm::dvec3 a(m.positions[t[0]]), b(m.positions[t[1]]), c(m.positions[t[2]]);
    const glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(glm::dvec3(d), e2);
    const double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-300) continue;
    const glm::dvec3 s = glm::dvec3(o) - a;
    const double u = glm::dot(s, p) / det;
    const glm::dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(glm::dvec3(d), q) / det;
    const double tt = glm::dot(e2, q) / det;
    if (u >= 0 && v >= 0 && u + v <= 1 && tt > 0 && tt < best) best = tt;
  }
  return static_cast<float>(best);
}

}  // namespace

TEST(SkeletonBvh, ClosestHitMatchesBruteForce) {
  const auto plate = skeleton::models::c_shape();
  const Mesh& m = plate.mesh;
  const detail::TriangleBvh bvh(m);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> box(-1.0f, 1.0f);
  int hits = 0;
  for (int i = 0; i < 400; ++i) {
    const glm::vec3 o(0.8f * box(rng), 0.8f * box(rng), 1.6f * box(rng));
    const glm::vec3 d = glm::normalize(glm::vec3(box(rng), box(rng), box(rng)));
    const float expected = brute_closest(m, o, d);
    const auto h = bvh.closest(o, d, 0.0f, 100.0f);
    if (!std::isfinite(expected)) {
      EXPECT_FALSE(h.found);
      continue;
    }
    ++hits;
    ASSERT_TRUE(h.found) << i;
    EXPECT_NEAR(h.t, expected, 1e-4f) << i;
  }
  EXPECT_GT(hits, 100);
}

TEST(SkeletonBvh, InsideAgreesWithTheImplicitTorus) {
  const Mesh m = shapes::torus(2.0f, 0.6f, 64, 24);
  const detail::TriangleBvh bvh(m);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> box(-3.0f, 3.0f);
  for (int i = 0; i < 300; ++i) {
    const glm::vec3 p(box(rng), box(rng), 0.3f * box(rng));
    const float f = shapes::torus_sdf(p, 2.0f, 0.6f);
    if (std::abs(f) < 0.05f) continue;  // the tessellation differs from the ideal surface
    EXPECT_EQ(bvh.inside(p), f < 0.0f) << p.x << ' ' << p.y << ' ' << p.z;
  }
}

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/core/topology.hpp"
#include "sdfkit/post/smooth.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace sdfkit;

namespace {
double variance(const std::vector<float>& v) {
  double m = 0, s = 0;
  for (float x : v) m += x;
  m /= v.size();
  for (float x : v) s += (x - m) * (x - m);
  return s / v.size();
}
}  // namespace

TEST(Smooth, ConstantFieldStaysConstant) {
  const Mesh m = shapes::icosphere(1, 3);
  const std::vector<float> v(m.positions.size(), 2.5f);
  for (float x : smooth_field(m, SdfDomain::Vertex, v, {})) EXPECT_NEAR(x, 2.5f, 1e-5f);
}

TEST(Smooth, ReducesNoiseMoreWithMoreRingsAndKeepsTheMean) {
  const Mesh m = shapes::icosphere(1, 4);
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  std::vector<float> v(m.positions.size());
  for (float& x : v) x = 5.0f + noise(rng);
  SmoothOptions one, three;
  one.rings = 1;
  three.rings = 3;
  const auto s1 = smooth_field(m, SdfDomain::Vertex, v, one);
  const auto s3 = smooth_field(m, SdfDomain::Vertex, v, three);
  EXPECT_LT(variance(s1), 0.5 * variance(v));
  EXPECT_LT(variance(s3), 0.5 * variance(s1));
  double mean = 0;
  for (float x : s3) mean += x;
  EXPECT_NEAR(mean / s3.size(), 5.0, 0.05);
}

TEST(Smooth, OneRingMatchesAHandComputation) {
  // Vertex 0 of a tetrahedron has every other vertex in its 1-ring.
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 2}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  const std::vector<float> v = {1, 2, 3, 4};
  SmoothOptions o;
  o.rings = 1;
  o.sigma = 1.0f;
  const auto s = smooth_field(m, SdfDomain::Vertex, v, o);
  const double w1 = std::exp(-0.5), w3 = std::exp(-2.0);
  EXPECT_NEAR(s[0], (1 + w1 * 2 + w1 * 3 + w3 * 4) / (1 + 2 * w1 + w3), 1e-5);
}

TEST(Smooth, WorksPerFaceAndThreadCountDoesNotChangeTheResult) {
  const Mesh m = shapes::torus(2, 0.5f, 48, 24);
  std::vector<float> v(m.triangles.size());
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<float>(i % 7);
  SmoothOptions a, b;
  a.threads = 1;
  b.threads = 2;
  EXPECT_EQ(smooth_field(m, SdfDomain::Face, v, a), smooth_field(m, SdfDomain::Face, v, b));
}

TEST(Smooth, RejectsBadArguments) {
  const Mesh m = shapes::box(1, 1, 1, 1);
  SmoothOptions o;
  o.rings = 0;
  EXPECT_THROW(smooth_field(m, SdfDomain::Vertex, std::vector<float>(m.positions.size()), o), InputError);
  EXPECT_THROW(smooth_field(m, SdfDomain::Vertex, std::vector<float>(3), {}), Error);
}

TEST(Smooth, FastGaussianWeightsMatchStdExp) {
  // The weights use an inlined exp; compare a smoothing against the definition with std::exp.
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 2}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  const std::vector<float> v = {1, 2, 3, 4};
  for (float sigma : {0.05f, 0.3f, 1.0f, 7.0f}) {
    SmoothOptions o;
    o.rings = 1;
    o.sigma = sigma;
    const auto s = smooth_field(m, SdfDomain::Vertex, v, o);
    double ws = 0, vs = 0;
    for (int j = 0; j < 4; ++j) {
      const double d2 = glm::dot(m.positions[j], m.positions[j]);
      const double w = std::exp(-d2 / (2.0 * sigma * sigma));
      ws += w;
      vs += w * v[j];
    }
    EXPECT_NEAR(s[0], vs / ws, 1e-5 * vs / ws) << sigma;
  }
}

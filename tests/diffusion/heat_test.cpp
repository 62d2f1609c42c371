// The heat-diffusion reference (sdfkit/diffusion/heat.hpp): analytic decay of a spherical
// harmonic, conservation of the mass-weighted total, constants kept, bad input refused.

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/diffusion/heat.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace sdfkit::diffusion {
namespace {

// u = z on the unit sphere is an eigenfunction of the Laplace-Beltrami operator (eigenvalue 2):
// `steps` implicit steps of t / steps scale it by (1 + 2 t / steps)^-steps, which converges to
// heat flow's exp(-2 t). The default (kHeatSteps) is heat flow itself to 0.006; at sigma 1.2 eight
// steps are 0.029 off, so the default cannot fall back to them unnoticed.
TEST(HeatDiffusion, SphericalHarmonicDecaysAsAnalytic) {
  const Mesh m = shapes::icosphere(1.0f, 4);
  std::vector<float> u(m.vertex_count());
  for (std::size_t v = 0; v < u.size(); ++v) u[v] = glm::normalize(m.positions[v]).z;
  for (const double sigma : {0.3, 0.7, 1.2}) {
    const double t = 0.5 * sigma * sigma;
    for (const int steps : {1, 8}) {
      const std::vector<float> h = heat_diffusion(m, u, sigma, steps);
      const double expect = std::pow(1.0 + 2.0 * t / steps, -steps);
      for (std::size_t v = 0; v < u.size(); ++v)
        if (std::abs(u[v]) > 0.5f) {
          ASSERT_NEAR(h[v] / u[v], expect, 0.01 * expect) << "sigma " << sigma << " steps " << steps;
        }
    }
    const std::vector<float> h = heat_diffusion(m, u, sigma);  // the reference: heat flow itself
    for (std::size_t v = 0; v < u.size(); ++v)
      if (std::abs(u[v]) > 0.5f) {
        ASSERT_NEAR(h[v] / u[v], std::exp(-2.0 * t), 0.006) << "sigma " << sigma;
      }
  }
}

// The implicit steps keep sum(M u) (1ᵀ L = 0) and keep constants; the values stay within the
// input's range on this mesh (no obtuse angles).
TEST(HeatDiffusion, KeepsTheMassWeightedTotalAndConstants) {
  const Mesh m = shapes::capped_cylinder(1.0f, 4.0f, 32, 20, 4);
  std::vector<double> mass(m.vertex_count(), 0.0);
  for (const auto& f : m.triangles) {
    const double a = 0.5 * glm::length(glm::cross(m.positions[f[1]] - m.positions[f[0]], m.positions[f[2]] - m.positions[f[0]]));
    for (std::uint32_t v : f) mass[v] += a / 3.0;
  }
  std::vector<float> u(m.vertex_count());
  for (std::size_t v = 0; v < u.size(); ++v) u[v] = m.positions[v].z > 0.0f ? 3.0f : 1.0f;
  const std::vector<float> h = heat_diffusion(m, u, 0.8);
  double before = 0.0, after = 0.0;
  for (std::size_t v = 0; v < u.size(); ++v) {
    before += mass[v] * u[v];
    after += mass[v] * h[v];
  }
  EXPECT_NEAR(after, before, 1e-5 * before);
  EXPECT_LT(h[0], 3.0f);  // something moved
  const std::vector<float> c = heat_diffusion(m, std::vector<float>(m.vertex_count(), 2.5f), 0.8);
  for (float x : c) ASSERT_NEAR(x, 2.5f, 1e-5f);
}

TEST(HeatDiffusion, BadInputIsAnInputError) {
  const Mesh m = shapes::icosphere(1.0f, 1);
  const std::vector<float> u(m.vertex_count(), 1.0f);
  EXPECT_THROW(heat_diffusion(m, std::vector<float>(3, 1.0f), 0.1), InputError);
  EXPECT_THROW(heat_diffusion(m, u, 0.0), InputError);
  EXPECT_THROW(heat_diffusion(m, u, std::nan("")), InputError);
  EXPECT_THROW(heat_diffusion(m, u, 0.1, 0), InputError);
  std::vector<float> bad = u;
  bad[2] = std::nanf("");
  EXPECT_THROW(heat_diffusion(m, bad, 0.1), InputError);
}

}  // namespace
}  // namespace sdfkit::diffusion

// The analytic estimator (sphere tracing on implicit shapes) against closed forms.
#include "analytic.hpp"

#include "sdfkit/core/shapes.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>

using namespace sdfkit;

TEST(Analytic, SphereMatchesTheClosedForm) {
  // Exact radial normals: at the defaults ray 17 of 30 lies at 44.9 degrees, 0.1 degree from
  // the sphere's 45-degree cut-off, so the closed form needs the true normal, not a facet's.
  const Mesh m = shapes::icosphere(3.0f, 3);
  SdfQuery q = make_query(m, SdfDomain::Vertex);
  for (std::size_t i = 0; i < q.size(); ++i) q.normals[i] = glm::normalize(q.origins[i]);
  for (FalseHitRule rule : {FalseHitRule::Paper, FalseHitRule::Cgal}) {
    SdfOptions o;
    o.false_hit = rule;
    const RawSdf raw = test::analytic_sdf(q, o, [](const glm::vec3& p) { return shapes::sphere_sdf(p, 3.0f); }, 6.0f);
    const float expected = test::sphere_closed_form(3.0f, o);
    for (std::size_t i = 0; i < q.size(); ++i) {
      EXPECT_NEAR(raw.values[i], expected, 1e-3f * expected) << i;
      EXPECT_GT(raw.kept_rays[i], 0u);
    }
  }
  // The paper's rule keeps 18 of 30 rays, whose chords are longer than the CGAL mean's.
  SdfOptions paper;
  SdfOptions cgal;
  cgal.false_hit = FalseHitRule::Cgal;
  EXPECT_GT(test::sphere_closed_form(3, paper), test::sphere_closed_form(3, cgal));
}

TEST(Analytic, SlabMatchesTheClosedForm) {
  // The middle of a wide thin box's top face: every ray crosses the thickness h at length
  // h / cos(theta) and both rules accept it.
  const float h = 1.0f;
  const Mesh m = shapes::box(40, 40, h, 8);
  const SdfQuery q = make_query(m, SdfDomain::Face);
  SdfOptions o;
  o.domain = SdfDomain::Face;
  const RawSdf raw = test::analytic_sdf(q, o, [&](const glm::vec3& p) { return shapes::box_sdf(p, {40, 40, h}); }, 60.0f);
  const float expected = test::slab_closed_form(h, o);
  int checked = 0;
  for (std::size_t i = 0; i < q.size(); ++i) {
    const glm::vec3 c = q.origins[i];
    if (std::fabs(c.z - h / 2) > 1e-4f || std::fabs(c.x) > 10 || std::fabs(c.y) > 10) continue;
    EXPECT_NEAR(raw.values[i], expected, 1e-3f * expected);
    ++checked;
  }
  EXPECT_GT(checked, 10);
}

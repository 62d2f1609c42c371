// The paper's Figure 7 model: a tube swept along a Bezier curve, its diameter growing linearly
// from 2 to 20. Away from the caps the SDF should follow the true local diameter (the paper saw
// deviations up to 10%; issue 2 aims for a median of at most 3%).
#include "compare.hpp"

#include "sdfkit/core/shapes.hpp"
#include "sdfkit/reference/embree_backend.hpp"

#include <gtest/gtest.h>

using namespace sdfkit;

namespace {

struct Deviation {
  double median = 0, q90 = 0, signed_median = 0, correlation = 0;
};

// SDF per vertex at the defaults with `rule`, against the true diameter, over the vertices of the
// rings with arc fraction in [0.1, 0.9] (cap vertices excluded).
Deviation tube_deviation(FalseHitRule rule) {
  const shapes::SweptTube tube = shapes::swept_tube(2.0f, 20.0f, 200, 64);
  reference::EmbreeBackend backend;
  backend.set_mesh(tube.mesh);
  SdfOptions o;
  o.false_hit = rule;
  const RawSdf raw = backend.compute(make_query(tube.mesh, SdfDomain::Vertex), o);
  std::vector<float> got, want;
  for (std::size_t v = 0; v < raw.values.size(); ++v) {
    if (tube.on_cap[v] || tube.arc_fraction[v] < 0.1f || tube.arc_fraction[v] > 0.9f) continue;
    got.push_back(raw.values[v]);
    want.push_back(tube.true_diameter[v]);
  }
  EXPECT_GT(got.size(), 10000u);
  return {test::median_relative_difference(got, want), test::quantile_relative_difference(got, want, 0.9),
          test::median_signed_relative_difference(got, want), test::pearson(got, want)};
}

}  // namespace

TEST(EmbreeSweptTube, PaperRuleFollowsTheTrueDiameter) {
  // Measured (200 rings x 64 segments, 30 rays, 120 degrees): median 0.54%, 90% within 1.5%,
  // worst 6.8%, no bias (-0.05%). Finer meshes (400 x 128) give the same numbers, and the
  // analytic estimator on an ideal straight cylinder deviates as much (median 0.55%): what is
  // left is the estimator's own sampling of a round section with 30 rays, not tessellation,
  // taper or bend.
  const Deviation d = tube_deviation(FalseHitRule::Paper);
  EXPECT_LT(d.median, 0.01);
  EXPECT_LT(d.q90, 0.03);
  EXPECT_LT(std::abs(d.signed_median), 0.01);
  EXPECT_GT(d.correlation, 0.999);
}

TEST(EmbreeSweptTube, CgalRuleUnderestimatesSlightly) {
  // CGAL's rule also keeps the rays that cross the circular section at 45 to 60 degrees to the
  // normal, whose chords 2 R cos(beta) are shorter than the diameter: a bias of about -2%
  // (measured median |dev| 1.9%, 90% within 2.8%), still within the 3%. On an ideal
  // straight cylinder the analytic estimator gives 1.3%; the taper and the bend add the rest.
  const Deviation d = tube_deviation(FalseHitRule::Cgal);
  EXPECT_LT(d.median, 0.03);
  EXPECT_LT(d.signed_median, 0.0);
  EXPECT_LT(d.q90, 0.04);
  EXPECT_GT(d.correlation, 0.999);
}

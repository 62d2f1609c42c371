// The OpenCL backend against the Embree reference on CGAL's real meshes: the same definition
// and ray set, so only float rounding (hit distances, edge cases of the triangle tests, rays at
// the sigma filter's edge) may differ.
#include "analytic.hpp"
#include "compare.hpp"
#include "device_fixture.hpp"

#include "sdfkit/io/asset.hpp"
#include "sdfkit/reference/embree_backend.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

using namespace sdfkit;

namespace {

struct Pair {
  RawSdf opencl, embree;
};

Pair run_both(cl::OpenClBackend& backend, const Mesh& mesh, const SdfOptions& o) {
  reference::EmbreeBackend embree;
  embree.set_mesh(mesh);
  backend.set_mesh(mesh);
  const SdfQuery q = make_query(mesh, o.domain);
  return {backend.compute(q, o), embree.compute(q, o)};
}

}  // namespace

class OpenClVsEmbree : public ::testing::TestWithParam<std::tuple<const char*, test::Tracer>> {};

TEST_P(OpenClVsEmbree, ValuesAgreePerVertexAndPerFace) {
  const char* name = std::get<0>(GetParam());
  SDFKIT_REQUIRE_CL_ACCEL(backend, std::get<1>(GetParam()));
  const Mesh mesh = io::load_asset(test::data_mesh(name)).mesh;
  for (SdfDomain domain : {SdfDomain::Vertex, SdfDomain::Face}) {
    for (FalseHitRule rule : {FalseHitRule::Paper, FalseHitRule::Cgal}) {
      SdfOptions o;
      o.domain = domain;
      o.false_hit = rule;
      const Pair p = run_both(backend, mesh, o);
      const SdfField a = finish_field(mesh, domain, p.opencl);
      const SdfField b = finish_field(mesh, domain, p.embree);
      const double med = test::median_relative_difference(a.values, b.values);
      const double r = test::pearson(a.values, b.values);
      EXPECT_LE(med, 0.01) << name << " domain " << int(domain) << " rule " << int(rule);
      EXPECT_GE(r, 0.99) << name << " domain " << int(domain) << " rule " << int(rule);
      // Same rays, same hits: nearly every point keeps the same number of rays.
      std::size_t same_kept = 0;
      for (std::size_t i = 0; i < a.values.size(); ++i) same_kept += p.opencl.kept_rays[i] == p.embree.kept_rays[i];
      EXPECT_GE(same_kept, a.values.size() * 95 / 100) << name;
    }
  }
}

auto param_name = [](const auto& param_info) {
  std::string s = param_info.param;
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
};

INSTANTIATE_TEST_SUITE_P(CgalMeshes, OpenClVsEmbree,
                         ::testing::Values(std::tuple{"elephant.off", test::Tracer::BvhBundles},
                                           std::tuple{"cow.off", test::Tracer::BvhBundles},
                                           std::tuple{"elephant.off", test::Tracer::BvhSingle},
                                           std::tuple{"elephant.off", test::Tracer::Octree}),
                         [](const auto& p) {
                           std::string s = std::string(std::get<0>(p.param)) + "_" +
                                           test::tracer_name(std::get<1>(p.param));
                           for (char& c : s)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return s;
                         });

// Tiny awkward meshes (an open cube; degenerate sliding triangles): too few points for
// statistics, so point by point. Rays of a cube's corner run exactly along edges and through
// the opposite corners, where two float triangle tests may disagree on a hit.
class OpenClVsEmbreeSmall : public ::testing::TestWithParam<const char*> {};

TEST_P(OpenClVsEmbreeSmall, PointsAgreeWhereTheSameRaysAreKept) {
  SDFKIT_REQUIRE_CL(backend);
  const Mesh mesh = io::load_asset(test::data_mesh(GetParam())).mesh;
  for (SdfDomain domain : {SdfDomain::Vertex, SdfDomain::Face}) {
    for (FalseHitRule rule : {FalseHitRule::Paper, FalseHitRule::Cgal}) {
      SdfOptions o;
      o.domain = domain;
      o.false_hit = rule;
      const Pair p = run_both(backend, mesh, o);
      std::size_t differ = 0;
      for (std::size_t i = 0; i < p.opencl.values.size(); ++i) {
        if (p.opencl.kept_rays[i] != p.embree.kept_rays[i]) {
          ++differ;
          continue;
        }
        EXPECT_NEAR(p.opencl.values[i], p.embree.values[i], 1e-4f * std::fabs(p.embree.values[i]))
            << GetParam() << " point " << i;
      }
      EXPECT_LE(differ, p.opencl.values.size() / 4) << GetParam();
    }
  }
}

INSTANTIATE_TEST_SUITE_P(CgalMeshes, OpenClVsEmbreeSmall,
                         ::testing::Values("cube-ouvert.off", "degtri_sliding.off"), param_name);

// Bundles (8 points per ray) and single rays trace the same rays with the same triangle test:
// the same lengths up to rounding (the single-ray test may contract into fma), except that a
// ray through a shared edge may take the other face at the same distance (and so get the
// other false-hit verdict).
TEST(OpenClBundles, AgreeWithSingleRays) {
  SDFKIT_REQUIRE_CL_ACCEL(bundles, test::Tracer::BvhBundles);
  SDFKIT_REQUIRE_CL_ACCEL(single, test::Tracer::BvhSingle);
  const Mesh mesh = io::load_asset(test::data_mesh("elephant.off")).mesh;
  for (SdfDomain domain : {SdfDomain::Vertex, SdfDomain::Face}) {
    for (int rays : {1, 8, 25}) {
      SdfOptions o;
      o.rays = rays;
      o.domain = domain;
      const SdfQuery q = make_query(mesh, domain);
      bundles.set_mesh(mesh);
      single.set_mesh(mesh);
      const RawSdf a = bundles.compute(q, o), b = single.compute(q, o);
      std::size_t same = 0;
      for (std::size_t i = 0; i < q.size(); ++i)
        same += a.kept_rays[i] == b.kept_rays[i] && std::fabs(a.values[i] - b.values[i]) <= 1e-5f * b.values[i];
      EXPECT_GE(same, q.size() * 999 / 1000) << "rays " << rays << ", domain " << int(domain);
    }
  }
}

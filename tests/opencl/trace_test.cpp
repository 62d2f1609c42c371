// The device's closest hit against a brute-force loop over all triangles: one ray per point
// (the gather of one length is that length), several cone apertures, a rotated mesh so no
// coordinate is special, and a mesh whose vertices lie on the octree's cell planes.
#include "device_fixture.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/shapes.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

using namespace sdfkit;

namespace {

// Closest Moller-Trumbore hit over all non-degenerate faces: t (INFINITY on a miss) and face.
float brute_force_hit(const Mesh& m, const std::vector<std::uint8_t>& degenerate, glm::vec3 o,
                      glm::vec3 d, std::size_t* face) {
  float best = INFINITY;
  for (std::size_t f = 0; f < m.triangles.size(); ++f) {
    if (degenerate[f]) continue;
    const auto& t = m.triangles[f];
    const glm::vec3 v0 = m.positions[t[0]], e1 = m.positions[t[1]] - v0, e2 = m.positions[t[2]] - v0;
    const glm::vec3 pv = glm::cross(d, e2);
    const float det = glm::dot(e1, pv);
    if (det == 0.0f) continue;
    const glm::vec3 tv = o - v0;
    const float u = glm::dot(tv, pv) / det;
    if (u < 0.0f || u > 1.0f) continue;
    const glm::vec3 qv = glm::cross(tv, e1);
    const float v = glm::dot(d, qv) / det;
    if (v < 0.0f || u + v > 1.0f) continue;
    const float tt = glm::dot(e2, qv) / det;
    if (tt > 0.0f && tt < best) {
      best = tt;
      *face = f;
    }
  }
  return best;
}

void expect_closest_hits(cl::OpenClBackend& backend, const Mesh& mesh) {
  backend.set_mesh(mesh);
  const auto degenerate = degenerate_faces(mesh);
  const auto fn = face_normals(mesh);
  for (SdfDomain domain : {SdfDomain::Vertex, SdfDomain::Face}) {
    const SdfQuery q = make_query(mesh, domain);
    for (float cone : {1.0f, 90.0f, 170.0f}) {
      SdfOptions o;
      o.rays = 1;
      o.cone_degrees = cone;
      o.false_hit = FalseHitRule::Cgal;
      const RawSdf got = backend.compute(q, o);
      const auto dirs = backend.ray_directions_for_test(q.normals, o);
      std::size_t mismatches = 0, hits = 0;
      for (std::size_t i = 0; i < q.size(); ++i) {
        if (!q.valid[i]) continue;
        const glm::vec3 d(dirs[i]);
        std::size_t f = 0;
        const float t = brute_force_hit(mesh, degenerate, q.origins[i] - q.origin_offset * q.normals[i], d, &f);
        const bool accepted = std::isfinite(t) && accept_hit(o.false_hit, q.normals[i], d, fn[f]);
        hits += accepted;
        // Rays through a shared edge may pick either face at the same t: compare t only.
        const bool same = accepted ? got.kept_rays[i] == 1 && std::fabs(got.values[i] - t) <= 1e-5f * t
                                   : got.kept_rays[i] == 0;
        mismatches += !same;
      }
      EXPECT_EQ(mismatches, 0u) << "cone " << cone << ", " << hits << " hits";
      EXPECT_GT(hits, q.size() / 2);
    }
  }
}

}  // namespace

class OpenClTrace : public ::testing::TestWithParam<test::Tracer> {};

TEST_P(OpenClTrace, ClosestHitEqualsBruteForceOnARotatedTorus) {
  SDFKIT_REQUIRE_CL_ACCEL(backend, GetParam());
  const Mesh mesh = shapes::torus(2.0f, 0.7f, 40, 20);
  const glm::vec3 k = glm::normalize(glm::vec3(-2, 1, 4));
  const float c = std::cos(1.1f), s = std::sin(1.1f), t = 1 - c;
  const float m[16] = {t * k.x * k.x + c,       t * k.x * k.y + s * k.z, t * k.x * k.z - s * k.y, 0,
                       t * k.x * k.y - s * k.z, t * k.y * k.y + c,       t * k.y * k.z + s * k.x, 0,
                       t * k.x * k.z + s * k.y, t * k.y * k.z - s * k.x, t * k.z * k.z + c,       0,
                       0.3f, 0.1f, -0.2f, 1};
  expect_closest_hits(backend, transformed(mesh, m));
}

TEST_P(OpenClTrace, ClosestHitEqualsBruteForceOnCellPlanes) {
  SDFKIT_REQUIRE_CL_ACCEL(backend, GetParam());
  // An axis-aligned box centred at the origin: faces, vertices and rays lie on the octree's
  // mid planes and directions have exact zero components.
  expect_closest_hits(backend, shapes::box(2.0f, 2.0f, 2.0f, 6));
  expect_closest_hits(backend, shapes::icosphere(1.0f, 3));
}

INSTANTIATE_TEST_SUITE_P(Tracer, OpenClTrace, ::testing::Values(test::Tracer::BvhBundles, test::Tracer::BvhSingle, test::Tracer::Octree),
                         [](const auto& p) { return std::string(test::tracer_name(p.param)); });

// A bundle work item's count of bundles (cl/sdf_trace.cl's SDFKIT_BUNDLES_PER_ITEM) only
// interleaves the bundles' traversal steps: each bundle visits the same nodes and tests the same
// triangles in the same order, so 1 (the GPU path), 2 and 4 (the CPU default) must agree bit for
// bit, including the last work item's missing bundles (405 and 810 bundles are no multiple of 4).
TEST(OpenClBundlesPerItem, EveryCountGivesTheSameSdfBitForBit) {
  if (cl::list_devices().empty()) {
    if (test::allow_no_device()) GTEST_SKIP() << "no OpenCL device (SDFKIT_ALLOW_NO_DEVICE=1)";
    FAIL() << "no OpenCL device; install pocl-opencl-icd or set SDFKIT_ALLOW_NO_DEVICE=1";
  }
  const Mesh mesh = shapes::torus(2.0f, 0.7f, 81, 40);
  std::vector<RawSdf> first;
  for (std::size_t per_item : {1, 2, 4}) {
    cl::OpenClConfig config;
    config.bvh_bundles = true;
    config.bvh_bundles_per_item = per_item;
    cl::OpenClBackend backend(config);
    backend.set_mesh(mesh);
    std::size_t k = 0;
    for (SdfDomain domain : {SdfDomain::Vertex, SdfDomain::Face}) {
      const SdfQuery q = make_query(mesh, domain);
      RawSdf got = backend.compute(q, SdfOptions{});
      if (per_item == 1) {
        std::size_t kept = 0;
        for (std::uint32_t r : got.kept_rays) kept += r;
        EXPECT_GT(kept, q.size() * 10) << "most rays of a torus hit its far wall";
        first.push_back(std::move(got));
        continue;
      }
      const RawSdf& want = first[k++];
      ASSERT_EQ(got.values.size(), want.values.size());
      std::size_t differ = 0;
      for (std::size_t i = 0; i < got.values.size(); ++i)
        differ += std::memcmp(&got.values[i], &want.values[i], sizeof(float)) != 0 ||
                  got.kept_rays[i] != want.kept_rays[i];
      EXPECT_EQ(differ, 0u) << per_item << " bundles per item, " << (domain == SdfDomain::Vertex ? "vertices" : "faces");
    }
  }
}

TEST(OpenClBundlesPerItem, RejectsACountTheKernelDoesNotHave) {
  cl::OpenClConfig config;
  config.bvh_bundles_per_item = 3;
  EXPECT_THROW(cl::OpenClBackend{config}, InputError);
}

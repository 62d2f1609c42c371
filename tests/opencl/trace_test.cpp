// The device's closest hit against a brute-force loop over all triangles: one ray per point
// (the gather of one length is that length), several cone apertures, a rotated mesh so no
// coordinate is special, and a mesh whose vertices lie on the octree's cell planes.
#include "device_fixture.hpp"

#include "sdfkit/core/shapes.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>

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

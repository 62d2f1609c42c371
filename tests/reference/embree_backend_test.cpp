// The Embree reference backend: interface behaviour, determinism, rotation invariance, open and
// degenerate meshes, position updates.
#include "analytic.hpp"
#include "compare.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/reference/embree_backend.hpp"

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

using namespace sdfkit;
using reference::EmbreeBackend;
using reference::EmbreeOptions;

namespace {

RawSdf run(EmbreeBackend& b, const Mesh& m, const SdfOptions& o = {}) {
  b.set_mesh(m);
  return b.compute(make_query(m, o.domain), o);
}

RawSdf run(const Mesh& m, const SdfOptions& o = {}, EmbreeOptions eo = {}) {
  EmbreeBackend b(eo);
  return run(b, m, o);
}

std::uint64_t total_kept(const RawSdf& r) {
  return std::accumulate(r.kept_rays.begin(), r.kept_rays.end(), std::uint64_t{0});
}

// Appends `extra`'s vertices and triangles to `base` (a second component).
Mesh combined(Mesh base, const Mesh& extra) {
  const auto offset = static_cast<std::uint32_t>(base.positions.size());
  base.positions.insert(base.positions.end(), extra.positions.begin(), extra.positions.end());
  for (Triangle t : extra.triangles) base.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  return base;
}

// A flat n x n grid of squares in the plane z = z0, spanning [x0, x0 + size] x [0, size], facing +z.
Mesh flat_grid(float x0, float z0, float size, int n) {
  Mesh m;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) m.positions.emplace_back(x0 + size * i / n, size * j / n, z0);
  auto id = [&](int i, int j) { return static_cast<std::uint32_t>(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

bool all_finite(const std::vector<float>& v) {
  return std::all_of(v.begin(), v.end(), [](float x) { return std::isfinite(x); });
}

}  // namespace

TEST(EmbreeBackend, NamesItselfAndItsDevice) {
  EmbreeBackend b(EmbreeOptions{3, 8});
  EXPECT_EQ(b.name(), "embree");
  EXPECT_EQ(b.thread_count(), 3u);
  EXPECT_NE(b.device_name().find("Embree 3."), std::string::npos) << b.device_name();
  EXPECT_NE(b.device_name().find("3 threads"), std::string::npos) << b.device_name();
}

TEST(EmbreeBackend, RejectsMisuse) {
  EXPECT_THROW(EmbreeBackend(EmbreeOptions{1, 5}), InputError);
  EmbreeBackend b;
  const Mesh m = shapes::icosphere(1.0f, 1);
  EXPECT_THROW(b.compute(make_query(m, SdfDomain::Vertex), {}), Error);
  EXPECT_THROW(b.update_positions(m.positions), Error);
  EXPECT_THROW(b.set_mesh(Mesh{}), InputError);
  b.set_mesh(m);
  EXPECT_THROW(b.update_positions(std::span(m.positions).first(3)), Error);
  SdfOptions bad;
  bad.rays = 0;
  EXPECT_THROW(b.compute(make_query(m, SdfDomain::Vertex), bad), InputError);
  SdfQuery q = make_query(m, SdfDomain::Vertex);
  q.normals.pop_back();
  EXPECT_THROW(b.compute(q, {}), InputError);
}

TEST(EmbreeBackend, ReportsStageTimings) {
  EmbreeBackend b;
  const Mesh m = shapes::icosphere(1.0f, 2);
  run(b, m);
  const auto t = b.last_timings();
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0].stage, "bvh_build");
  EXPECT_EQ(t[1].stage, "trace_gather");
  EXPECT_GE(t[0].milliseconds, 0.0);
  EXPECT_GE(t[1].milliseconds, 0.0);
  EXPECT_GT(b.device_memory_bytes(), 0u);  // the BVH lives through compute()
}

TEST(EmbreeBackend, DeterministicForAnyThreadCountAndRun) {
  const Mesh m = shapes::swept_tube(2.0f, 20.0f, 60, 24).mesh;
  for (int packet : {1, 8, 16}) {
    SCOPED_TRACE(packet);
    for (SdfDomain domain : {SdfDomain::Vertex, SdfDomain::Face}) {
      SdfOptions o;
      o.domain = domain;
      const RawSdf one = run(m, o, {1, packet});
      EmbreeBackend many(EmbreeOptions{7, packet});
      const RawSdf a = run(many, m, o);
      const RawSdf b = many.compute(make_query(m, domain), o);
      ASSERT_EQ(one.values.size(), a.values.size());
      // Bit-identical, not merely close.
      EXPECT_EQ(0, std::memcmp(one.values.data(), a.values.data(), a.values.size() * sizeof(float)));
      EXPECT_EQ(one.kept_rays, a.kept_rays);
      EXPECT_EQ(0, std::memcmp(a.values.data(), b.values.data(), a.values.size() * sizeof(float)));
    }
  }
}

TEST(EmbreeBackend, PacketSizesAgreeToRounding) {
  const Mesh m = shapes::torus(2.0f, 0.5f, 48, 16);
  const RawSdf single = run(m, {}, {2, 1});
  for (int packet : {4, 8, 16}) {
    const RawSdf p = run(m, {}, {2, packet});
    EXPECT_LT(test::quantile_relative_difference(p.values, single.values, 1.0), 1e-5) << packet;
  }
}

TEST(EmbreeBackend, RotationChangesValuesOnlyWithinSamplingNoise) {
  // The tangent frame is not rotation-equivariant, so a rotated mesh is probed by rays at other
  // azimuths: values move by sampling noise, not systematically. The swept tube's diameter
  // varies tenfold, so the correlation is meaningful. Near the flat caps' sharp rims a ray more
  // or less grazing the rim moves single values a lot (measured up to 4x), so the correlation
  // is taken over the tube's body; the median covers every point (measured 0.75%).
  const shapes::SweptTube tube = shapes::swept_tube(2.0f, 20.0f, 100, 32);
  const Mesh& m = tube.mesh;
  const glm::mat4 r = glm::rotate(glm::mat4(1.0f), 0.83f, glm::normalize(glm::vec3(1.0f, -2.0f, 0.7f)));
  float rm[16];
  std::memcpy(rm, glm::value_ptr(r), sizeof rm);
  const Mesh rotated = transformed(m, rm);
  auto body_vertex = [&](std::uint32_t v) {
    return !tube.on_cap[v] && tube.arc_fraction[v] > 0.05f && tube.arc_fraction[v] < 0.95f;
  };
  for (SdfDomain domain : {SdfDomain::Vertex, SdfDomain::Face}) {
    SdfOptions o;
    o.domain = domain;
    const RawSdf a = run(m, o), b = run(rotated, o);
    EXPECT_LT(test::median_relative_difference(b.values, a.values), 0.01);
    EXPECT_LT(test::quantile_relative_difference(b.values, a.values, 0.9), 0.05);
    std::vector<float> body_a, body_b;
    for (std::size_t i = 0; i < a.values.size(); ++i) {
      const bool body = domain == SdfDomain::Vertex
                            ? body_vertex(static_cast<std::uint32_t>(i))
                            : std::all_of(m.triangles[i].begin(), m.triangles[i].end(), body_vertex);
      if (!body) continue;
      body_a.push_back(a.values[i]);
      body_b.push_back(b.values[i]);
    }
    EXPECT_GT(body_a.size(), a.values.size() / 2);
    EXPECT_GT(test::pearson(body_b, body_a), 0.99);
  }
}

TEST(EmbreeBackend, OpenMeshGetsFewerRaysAndFillsPointsWithoutHits) {
  // A bowl (an icosphere with its top cut off) loses the rays that leave through the opening;
  // a flat square beside it, whose rays all go into empty space, has no value at all.
  const Mesh sphere = shapes::icosphere(1.0f, 3);
  Mesh bowl{sphere.positions, {}};
  const auto centroids = face_centroids(sphere);
  for (std::size_t f = 0; f < sphere.triangles.size(); ++f)
    if (centroids[f].z < 0.5f) bowl.triangles.push_back(sphere.triangles[f]);
  const RawSdf closed = run(sphere), open = run(bowl);
  EXPECT_LT(total_kept(open), total_kept(closed));
  EXPECT_TRUE(all_finite(open.values));

  const Mesh grid = flat_grid(5.0f, 0.0f, 1.0f, 4);
  const Mesh scene = combined(bowl, grid);
  EmbreeBackend b;
  b.set_mesh(scene);
  for (SdfDomain domain : {SdfDomain::Vertex, SdfDomain::Face}) {
    SdfOptions o;
    o.domain = domain;
    const RawSdf raw = b.compute(make_query(scene, domain), o);
    const std::size_t first_grid = domain == SdfDomain::Vertex ? bowl.vertex_count() : bowl.face_count();
    for (std::size_t i = first_grid; i < raw.values.size(); ++i) EXPECT_EQ(raw.kept_rays[i], 0u) << i;
    const SdfField field = compute_sdf(b, scene, o);
    EXPECT_TRUE(all_finite(field.values));
    EXPECT_GE(field.filled_count, raw.values.size() - first_grid);
    for (std::size_t i = first_grid; i < raw.values.size(); ++i) {
      EXPECT_TRUE(field.filled[i]);
      EXPECT_GT(field.values[i], 0.0f);
    }
  }
}

TEST(EmbreeBackend, DegenerateFacesAreNeitherTargetsNorOrigins) {
  // Degenerate triangles added to a sphere: one repeating a vertex, one whose corners sit on a
  // line inside the sphere. Nothing they touch may change, and they themselves get filled.
  const Mesh sphere = shapes::icosphere(1.0f, 3);
  Mesh m = sphere;
  const auto v0 = static_cast<std::uint32_t>(m.positions.size());
  m.positions.insert(m.positions.end(), {{-0.3f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, {0.3f, 0.0f, 0.0f}});
  m.triangles.push_back({0, 0, 1});
  m.triangles.push_back({v0, v0 + 1, v0 + 2});
  m.triangles.push_back({v0, v0 + 2, v0 + 1});  // both orientations: the line cuts every ray's path
  const std::vector<std::uint8_t> degenerate = degenerate_faces(m);
  ASSERT_EQ(std::count(degenerate.begin(), degenerate.end(), 1), 3);

  for (SdfDomain domain : {SdfDomain::Vertex, SdfDomain::Face}) {
    SdfOptions o;
    o.domain = domain;
    const RawSdf plain = run(sphere, o), with = run(m, o);
    const std::size_t n = plain.values.size();
    ASSERT_EQ(with.values.size(), n + 3);
    EXPECT_TRUE(all_finite(with.values));
    for (std::size_t i = 0; i < n; ++i) EXPECT_FLOAT_EQ(with.values[i], plain.values[i]) << i;
    for (std::size_t i = n; i < n + 3; ++i) EXPECT_EQ(with.kept_rays[i], 0u) << i;
    EmbreeBackend b;
    b.set_mesh(m);
    const SdfField field = compute_sdf(b, m, o);
    EXPECT_TRUE(all_finite(field.values));
    EXPECT_EQ(field.filled_count, 3u);
  }
}

TEST(EmbreeBackend, UpdatePositionsEqualsAFreshMesh) {
  const Mesh m = shapes::torus(2.0f, 0.5f, 48, 16);
  Mesh moved = m;
  for (glm::vec3& p : moved.positions) p = glm::vec3(1.3f * p.x, p.y + 0.1f * std::sin(3.0f * p.x), 0.8f * p.z);
  for (SdfDomain domain : {SdfDomain::Vertex, SdfDomain::Face}) {
    SdfOptions o;
    o.domain = domain;
    EmbreeBackend updated;
    run(updated, m, o);
    updated.update_positions(moved.positions);
    const RawSdf a = updated.compute(make_query(moved, domain), o);
    const RawSdf fresh = run(moved, o);
    // A refitted BVH visits triangles in another order than a fresh one, which can only matter
    // for a ray through a shared edge (equal distances): values agree to rounding.
    EXPECT_LT(test::quantile_relative_difference(a.values, fresh.values, 1.0), 1e-6);
    EXPECT_EQ(a.kept_rays, fresh.kept_rays);
    // And they differ from the unmoved mesh's.
    EXPECT_GT(test::median_relative_difference(a.values, run(m, o).values), 0.01);
  }
}

TEST(EmbreeBackend, UpdatePositionsThatMakeAFaceDegenerateRebuilds) {
  Mesh m = shapes::icosphere(1.0f, 2);
  Mesh moved = m;
  const Triangle t = moved.triangles[5];
  moved.positions[t[1]] = moved.positions[t[0]];  // collapses the triangles around that edge
  EmbreeBackend b;
  b.set_mesh(m);
  b.update_positions(moved.positions);
  SdfOptions o;
  o.domain = SdfDomain::Face;
  const RawSdf a = b.compute(make_query(moved, o.domain), o);
  const RawSdf fresh = run(moved, o);
  EXPECT_TRUE(all_finite(a.values));
  EXPECT_LT(test::quantile_relative_difference(a.values, fresh.values, 1.0), 1e-6);
  EXPECT_EQ(a.kept_rays, fresh.kept_rays);
  EXPECT_EQ(a.kept_rays[5], 0u);
}

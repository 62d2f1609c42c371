// The OpenCL backend's behaviour on awkward input and across calls: rotation, open and
// degenerate meshes, no hits at all, moved vertices, batching, device selection.
#include "compare.hpp"
#include "device_fixture.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/opencl/bvh.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <filesystem>
#include <string>

using namespace sdfkit;

TEST(OpenClRobustness, RotationInvariant) {
  SDFKIT_REQUIRE_CL(backend);
  // The paper's swept tube: diameters from 2 to 20, so the field varies and correlation means
  // something. The estimator itself is invariant only statistically: the ray pattern's phase
  // around the normal comes from tangent_frame(-n), which does not rotate with the mesh, rays at
  // the sigma filter's edge flip, and the start offset follows the bounding box. So the fields
  // are compared as a whole, and their means must agree closely (no direction-dependent bias;
  // the unrotated tube, whose normals share one plane, sees one ray phase everywhere: 0.7%).
  const Mesh mesh = shapes::swept_tube(2.0f, 20.0f, 100, 32).mesh;
  // A rotation by 0.7 rad about the unit axis (1, 2, 3) / sqrt(14), then a translation.
  const glm::vec3 k = glm::normalize(glm::vec3(1, 2, 3));
  const float c = std::cos(0.7f), s = std::sin(0.7f), t = 1 - c;
  const float m[16] = {t * k.x * k.x + c,       t * k.x * k.y + s * k.z, t * k.x * k.z - s * k.y, 0,
                       t * k.x * k.y - s * k.z, t * k.y * k.y + c,       t * k.y * k.z + s * k.x, 0,
                       t * k.x * k.z + s * k.y, t * k.y * k.z - s * k.x, t * k.z * k.z + c,       0,
                       5, -2, 1, 1};
  const Mesh rotated = transformed(mesh, m);
  for (FalseHitRule rule : {FalseHitRule::Paper, FalseHitRule::Cgal})
    for (SdfDomain domain : {SdfDomain::Vertex, SdfDomain::Face}) {
      SdfOptions o;
      o.domain = domain;
      o.false_hit = rule;
      backend.set_mesh(mesh);
      const SdfField a = compute_sdf(backend, mesh, o);
      backend.set_mesh(rotated);
      const SdfField b = compute_sdf(backend, rotated, o);
      EXPECT_LE(test::median_relative_difference(b.values, a.values), 0.02);
      EXPECT_LE(test::quantile_relative_difference(b.values, a.values, 0.9), 0.05);
      EXPECT_GE(test::pearson(b.values, a.values), 0.97);
      double sa = 0, sb = 0;
      for (std::size_t i = 0; i < a.values.size(); ++i) {
        sa += a.values[i];
        sb += b.values[i];
      }
      EXPECT_NEAR(sb / sa, 1.0, 0.015);
    }
}

TEST(OpenClRobustness, OpenMeshGivesFiniteValues) {
  SDFKIT_REQUIRE_CL(backend);
  // A cylinder without its caps: rays near the open ends escape.
  const float radius = 1.0f;
  const Mesh closed = shapes::capped_cylinder(radius, 8.0f, 48, 40, 4);
  const auto normals = face_normals(closed);
  Mesh open;
  open.positions = closed.positions;
  for (std::size_t f = 0; f < closed.triangles.size(); ++f)
    if (std::fabs(normals[f].z) < 0.5f) open.triangles.push_back(closed.triangles[f]);
  backend.set_mesh(open);
  SdfOptions o;
  o.false_hit = FalseHitRule::Cgal;
  const SdfField f = compute_sdf(backend, open, o);
  std::vector<float> middle;
  for (std::size_t v = 0; v < open.positions.size(); ++v) {
    ASSERT_TRUE(std::isfinite(f.values[v])) << v;
    if (std::fabs(open.positions[v].z) < 1.0f && f.kept_rays[v] > 0) middle.push_back(f.values[v]);
  }
  // Away from the ends every ray crosses the tube: the value is a chord of the circle, between
  // the radius and the diameter / cos(60 degrees).
  ASSERT_GT(middle.size(), 100u);
  const float m = median_of(middle);
  EXPECT_GT(m, radius);
  EXPECT_LT(m, 2.0f * radius);
}

TEST(OpenClRobustness, DegenerateFacesChangeNothing) {
  SDFKIT_REQUIRE_CL(backend);
  const Mesh clean = shapes::icosphere(2.0f, 3);
  Mesh dirty = clean;
  const auto n = static_cast<std::uint32_t>(clean.positions.size());
  dirty.positions.push_back(clean.positions[0] * 0.5f);                      // isolated vertex
  dirty.positions.push_back((clean.positions[0] + clean.positions[5]) * 0.5f);  // on a chord
  dirty.triangles.push_back({0, 0, 5});       // repeated index
  dirty.triangles.push_back({0, n + 1, 5});   // collinear: zero area
  dirty.triangles.push_back({n, n, n});       // a point
  SdfOptions o;
  backend.set_mesh(clean);
  const RawSdf a = backend.compute(make_query(clean, SdfDomain::Vertex), o);
  backend.set_mesh(dirty);
  const RawSdf b = backend.compute(make_query(dirty, SdfDomain::Vertex), o);
  for (std::size_t v = 0; v < clean.positions.size(); ++v) {
    EXPECT_EQ(a.values[v], b.values[v]) << v;
    EXPECT_EQ(a.kept_rays[v], b.kept_rays[v]) << v;
  }
  EXPECT_EQ(b.kept_rays[n], 0u);  // the isolated vertex casts no ray
  o.domain = SdfDomain::Face;
  const SdfField f = compute_sdf(backend, dirty, o);
  for (std::size_t t = clean.triangles.size(); t < dirty.triangles.size(); ++t) {
    EXPECT_EQ(f.kept_rays[t], 0u);
    EXPECT_EQ(f.filled[t], 1u);
    EXPECT_TRUE(std::isfinite(f.values[t]));
  }
}

TEST(OpenClRobustness, NoHitsAtAllAreFilled) {
  SDFKIT_REQUIRE_CL(backend);
  Mesh tri;
  tri.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  tri.triangles = {{0, 1, 2}};
  backend.set_mesh(tri);
  for (SdfDomain domain : {SdfDomain::Vertex, SdfDomain::Face}) {
    SdfOptions o;
    o.domain = domain;
    const SdfQuery q = make_query(tri, domain);
    const RawSdf raw = backend.compute(q, o);
    for (std::uint32_t k : raw.kept_rays) EXPECT_EQ(k, 0u);
    const SdfField f = compute_sdf(backend, tri, o);
    EXPECT_EQ(f.filled_count, q.size());
    for (float v : f.values) EXPECT_EQ(v, 0.0f);
  }
}

class OpenClUpdate : public ::testing::TestWithParam<test::Tracer> {};

TEST_P(OpenClUpdate, UpdatePositionsEqualsFreshSetMesh) {
  SDFKIT_REQUIRE_CL_ACCEL(backend, GetParam());
  const Mesh before = shapes::capsule(1.0f, 3.0f, 40, 20);
  Mesh after = before;
  for (glm::vec3& p : after.positions)
    p = glm::vec3(p.x * (1.0f + 0.3f * p.z), p.y * 0.7f, p.z + 0.2f * std::sin(3.0f * p.x));
  SdfOptions o;
  backend.set_mesh(before);
  (void)backend.compute(make_query(before, SdfDomain::Vertex), o);
  backend.update_positions(after.positions);
  const RawSdf moved = backend.compute(make_query(after, SdfDomain::Vertex), o);
  backend.set_mesh(after);
  const RawSdf fresh = backend.compute(make_query(after, SdfDomain::Vertex), o);
  EXPECT_EQ(moved.values, fresh.values);
  EXPECT_EQ(moved.kept_rays, fresh.kept_rays);
  EXPECT_THROW(backend.update_positions(std::vector<glm::vec3>(3)), Error);
}

// update_positions refits the BVH for a small move, rebuilds it for a distortion that would
// leave a refit tree much worse than a new one, and rebuilds when a degenerate triangle gets an
// area; every way gives the values of a fresh set_mesh.
TEST(OpenClUpdate, RefitsSmallMovesAndRebuildsLargeOnes) {
  SDFKIT_REQUIRE_CL_ACCEL(backend, test::Tracer::BvhBundles);
  Mesh base = shapes::capsule(1.0f, 3.0f, 40, 20);
  const auto n = static_cast<std::uint32_t>(base.positions.size());
  base.positions.push_back({0.0f, 0.0f, 0.0f});  // a degenerate triangle inside
  base.positions.push_back({0.1f, 0.0f, 0.0f});
  base.positions.push_back({0.2f, 0.0f, 0.0f});
  base.triangles.push_back({n, n + 1, n + 2});
  auto moved = [&](auto f) {
    Mesh m = base;
    for (std::size_t i = 0; i < n; ++i) m.positions[i] = f(m.positions[i]);
    return m;
  };
  const Mesh nudged = moved([](glm::vec3 p) { return p * 1.02f + glm::vec3(0.01f * p.z, 0, 0); });
  // Folds the capsule onto itself: parts far apart in the tree now overlap.
  const Mesh folded = moved([](glm::vec3 p) { return glm::vec3(p.x, p.y, std::sin(6.0f * p.z)); });
  const Mesh opened = [&] {
    Mesh m = base;
    m.positions[n + 1].y = 0.1f;
    return m;
  }();
  SdfOptions o;
  for (const auto& [mesh, stage] : {std::pair{&nudged, "bvh_refit"}, std::pair{&folded, "bvh_build"},
                                    std::pair{&opened, "bvh_build"}}) {
    backend.set_mesh(base);
    backend.update_positions(mesh->positions);
    EXPECT_EQ(backend.last_timings().front().stage, stage);
    const RawSdf updated = backend.compute(make_query(*mesh, SdfDomain::Vertex), o);
    backend.set_mesh(*mesh);
    EXPECT_EQ(backend.last_timings().front().stage, "bvh_build");
    const RawSdf fresh = backend.compute(make_query(*mesh, SdfDomain::Vertex), o);
    EXPECT_EQ(updated.values, fresh.values) << stage;
    EXPECT_EQ(updated.kept_rays, fresh.kept_rays) << stage;
  }
}

INSTANTIATE_TEST_SUITE_P(Tracer, OpenClUpdate, ::testing::Values(test::Tracer::BvhBundles, test::Tracer::BvhSingle, test::Tracer::Octree),
                         [](const auto& p) { return std::string(test::tracer_name(p.param)); });

TEST(OpenClRobustness, SmallMemoryCapBatchesWithoutChangingResults) {
  SDFKIT_REQUIRE_CL(shared);
  cl::OpenClConfig config;
  config.device = std::to_string(shared.device().index);
  config.memory_cap = 100 * (2 * 16 + 30 * 8 + 8) + 5;  // 100 points of 30 rays per batch
  cl::OpenClBackend small(config);
  EXPECT_EQ(small.batch_points(30), 100u);
  const Mesh mesh = shapes::icosphere(1.0f, 3);  // 642 vertices: 7 batches
  small.set_mesh(mesh);
  shared.set_mesh(mesh);
  const SdfQuery q = make_query(mesh, SdfDomain::Vertex);
  const RawSdf a = small.compute(q, {});
  const RawSdf b = shared.compute(q, {});
  EXPECT_EQ(a.values, b.values);
  EXPECT_EQ(a.kept_rays, b.kept_rays);
  EXPECT_GT(small.device_memory_bytes(), 0u);
}

// Configuration values out of range are refused before any device work, with InputError.
TEST(OpenClRobustness, BadConfigurationIsAnInputError) {
  auto with = [](auto change) {
    cl::OpenClConfig c;
    change(c);
    return c;
  };
  EXPECT_THROW(cl::OpenClBackend{with([](auto& c) { c.memory_cap = 0; })}, InputError);
  EXPECT_THROW(cl::OpenClBackend{with([](auto& c) { c.bvh_leaf_size = -1; })}, InputError);
  EXPECT_THROW(cl::OpenClBackend{with([](auto& c) { c.bvh_traversal_cost = -1.0f; })}, InputError);
  EXPECT_THROW(cl::OpenClBackend{with([](auto& c) { c.bvh_traversal_cost = NAN; })}, InputError);
  EXPECT_THROW(cl::OpenClBackend{with([](auto& c) { c.bvh_refit_limit = -0.5; })}, InputError);
  EXPECT_THROW(cl::OpenClBackend{with([](auto& c) { c.bvh_refit_limit = INFINITY; })}, InputError);
  EXPECT_THROW(sdfkit::cl::build_bvh(shapes::icosphere(1.0f, 1), {4, 0.0f}), InputError);
}

TEST(OpenClRobustness, DeviceSelectionByIndexNameAndUnknown) {
  SDFKIT_REQUIRE_CL(shared);
  (void)shared;
  const auto devices = cl::list_devices();
  ASSERT_FALSE(devices.empty());
  cl::OpenClConfig by_name;
  by_name.device = devices[0].name.substr(0, 4);
  for (char& ch : by_name.device) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  EXPECT_NO_THROW(cl::OpenClBackend{by_name});
  cl::OpenClConfig unknown;
  unknown.device = "no-such-device-xyz";
  try {
    cl::OpenClBackend b(unknown);
    FAIL() << "an unknown device was accepted";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("available devices"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(devices[0].name), std::string::npos) << e.what();
  }
  unknown.device = std::to_string(devices.size());
  EXPECT_THROW(cl::OpenClBackend{unknown}, DeviceError);
}

// Without any OpenCL platform (the ICD loader pointed at an empty vendor directory, in a child
// process so this process's loader stays as it is): list_devices() is empty and the backend
// refuses with the sentence naming the packages to install.
TEST(OpenClRobustness, NoPlatformGivesTheInstallSentence) {
  if (const char* child = std::getenv("SDFKIT_TEST_NO_PLATFORM_CHILD"); child && std::string(child) == "1") {
    EXPECT_TRUE(cl::list_devices().empty());
    try {
      cl::OpenClBackend b;
      ADD_FAILURE() << "a backend was created without a platform";
    } catch (const DeviceError& e) {
      EXPECT_NE(std::string(e.what()).find("pocl-opencl-icd"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("no OpenCL platform found"), std::string::npos) << e.what();
    }
    return;
  }
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  const std::string cmd = "SDFKIT_TEST_NO_PLATFORM_CHILD=1 OCL_ICD_VENDORS=/nonexistent-sdfkit-vendors '" +
                          self + "' --gtest_filter=OpenClRobustness.NoPlatformGivesTheInstallSentence >/dev/null 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
}

// A shared mesh (what a Session gives) builds the same geometry as a lent one, the BVH's nodes
// read back from the device are the tree that traces, a refit after set_shared_mesh reads them
// back and matches a fresh build, and after release_mesh compute still works while
// update_positions asks for a new set_mesh.
TEST(OpenClRobustness, SharedMeshMatchesLentMeshAndCanBeReleased) {
  SDFKIT_REQUIRE_CL(backend);
  const Mesh base = shapes::capsule(1.0f, 3.0f, 40, 20);
  const SdfQuery q = make_query(base, SdfDomain::Vertex);
  backend.set_mesh(base);
  const RawSdf lent = backend.compute(q, {});
  const cl::Bvh lent_bvh = backend.bvh();
  backend.set_shared_mesh(std::make_shared<const Mesh>(base));
  const RawSdf shared = backend.compute(q, {});
  EXPECT_EQ(lent.values, shared.values);
  EXPECT_EQ(lent.kept_rays, shared.kept_rays);
  const cl::Bvh& tree = backend.bvh();  // nodes read back from the device
  ASSERT_FALSE(tree.nodes.empty());
  ASSERT_EQ(tree.nodes.size(), lent_bvh.nodes.size());
  EXPECT_EQ(0, std::memcmp(tree.nodes.data(), lent_bvh.nodes.data(), tree.nodes.size() * sizeof(cl::BvhNode)));
  EXPECT_EQ(tree.order, lent_bvh.order);
  EXPECT_DOUBLE_EQ(cl::sah_cost(tree), cl::sah_cost(cl::build_bvh(base, {16, 3.0f})));

  Mesh nudged = base;
  for (glm::vec3& p : nudged.positions) p = p * 1.02f + glm::vec3(0.01f * p.z, 0, 0);
  backend.update_positions(nudged.positions);
  EXPECT_EQ(backend.last_timings().front().stage, "bvh_refit");
  const SdfQuery qn = make_query(nudged, SdfDomain::Vertex);
  const RawSdf refit = backend.compute(qn, {});
  backend.set_mesh(nudged);
  const RawSdf fresh = backend.compute(qn, {});
  EXPECT_EQ(refit.values, fresh.values);
  EXPECT_EQ(refit.kept_rays, fresh.kept_rays);

  backend.set_shared_mesh(std::make_shared<const Mesh>(base));
  backend.release_mesh();
  const RawSdf after = backend.compute(q, {});
  EXPECT_EQ(after.values, lent.values);
  EXPECT_THROW(backend.update_positions(base.positions), Error);
  // What only a refit reads is gone with the mesh; the tree that traces is not.
  EXPECT_TRUE(backend.bvh().order.empty());
  EXPECT_EQ(backend.bvh().nodes.size(), lent_bvh.nodes.size());
  backend.set_mesh(base);  // leaves the shared backend as the other tests expect it
}

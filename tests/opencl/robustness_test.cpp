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

// Refits in a row (the skeleton's contraction: the capsule shrinks step by step, every step a
// refit of the tree built for the first shape) give, step by step, the values of a fresh
// set_mesh of the same positions: a closest hit does not depend on the tree's shape. At step 3
// a bundle ray of vertex 1561 runs through the edge two mirror-image triangles share (y = 0)
// and hits both at bitwise the same distance; which one wins (their normals differ in y, so
// one passes the false-hit rule and one does not) once depended on which leaf was visited first.
TEST_P(OpenClUpdate, RefitsInARowEqualFreshSetMesh) {
  SDFKIT_REQUIRE_CL_ACCEL(backend, GetParam());
  const Mesh base = shapes::capsule(1.0f, 3.0f, 40, 20);
  std::vector<Mesh> steps;
  for (int step = 1; step <= 3; ++step) {
    const float s = 1.0f - 0.08f * static_cast<float>(step);
    Mesh m = base;
    for (glm::vec3& p : m.positions) p = glm::vec3(p.x * s, p.y * s * s, p.z);
    steps.push_back(std::move(m));
  }
  SdfOptions o;
  o.rays = 4;
  backend.set_mesh(base);
  std::vector<RawSdf> refit;
  for (const Mesh& m : steps) {
    backend.update_positions(m.positions);
    if (GetParam() != test::Tracer::Octree) {
      EXPECT_EQ(backend.last_timings().front().stage, "bvh_refit");
    }
    refit.push_back(backend.compute(make_query(m, SdfDomain::Vertex), o));
  }
  for (std::size_t i = 0; i < steps.size(); ++i) {
    backend.set_mesh(steps[i]);
    const RawSdf fresh = backend.compute(make_query(steps[i], SdfDomain::Vertex), o);
    std::size_t differ = 0;
    for (std::size_t v = 0; v < fresh.values.size(); ++v)
      if (refit[i].values[v] != fresh.values[v] || refit[i].kept_rays[v] != fresh.kept_rays[v]) {
        if (differ++ < 5)
          ADD_FAILURE() << "step " << i + 1 << " vertex " << v << ": refit " << refit[i].values[v] << " ("
                        << refit[i].kept_rays[v] << " rays), fresh " << fresh.values[v] << " ("
                        << fresh.kept_rays[v] << " rays)";
      }
    EXPECT_EQ(differ, 0u) << "step " << i + 1;
  }
}

// The skeleton's contraction: one update_positions per iteration, each refitting the tree of
// the last (kept on the host; its upload is not waited for). Two updates in a row, without a
// compute between them, give the values of the same updates each followed by a compute.
TEST_P(OpenClUpdate, UpdatesInARowEqualUpdatesEachComputed) {
  SDFKIT_REQUIRE_CL_ACCEL(backend, GetParam());
  const Mesh base = shapes::capsule(1.0f, 3.0f, 40, 20);
  SdfOptions o;
  o.rays = 4;
  std::vector<Mesh> steps;
  for (int step = 1; step <= 6; ++step) {
    const float s = 1.0f - 0.08f * static_cast<float>(step);  // shrinks toward the axis
    Mesh m = base;
    for (glm::vec3& p : m.positions) p = glm::vec3(p.x * s, p.y * s * s, p.z);
    steps.push_back(std::move(m));
  }
  std::vector<RawSdf> each;
  backend.set_mesh(base);
  for (const Mesh& m : steps) {
    backend.update_positions(m.positions);
    each.push_back(backend.compute(make_query(m, SdfDomain::Vertex), o));
  }
  backend.set_mesh(base);
  std::size_t compared = 0;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    backend.update_positions(steps[i].positions);
    if (i % 3 == 0) continue;  // two updates before the next compute
    const RawSdf updated = backend.compute(make_query(steps[i], SdfDomain::Vertex), o);
    EXPECT_EQ(updated.values, each[i].values) << "step " << i;
    EXPECT_EQ(updated.kept_rays, each[i].kept_rays) << "step " << i;
    ++compared;
  }
  EXPECT_EQ(compared, 4u);
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

// Bundles trace a 4-wide copy of the BVH; the host keeps the binary tree only up to 2^19 nodes.
// A larger mesh (an icosphere of 1.3M triangles) keeps none, so update_positions rebuilds
// instead of refitting, and the values still equal a fresh set_mesh's (on a sample of points).
TEST(OpenClUpdateLarge, RebuildsWithoutAHostTreeAndMatchesAFreshBuild) {
  SDFKIT_REQUIRE_CL(backend);
  const Mesh base = shapes::icosphere(1.0f, 8);
  Mesh moved = base;
  for (glm::vec3& p : moved.positions) p = p * 1.02f + glm::vec3(0.01f * p.z, 0, 0);
  const auto sample = [](const Mesh& m) {
    SdfQuery all = make_query(m, SdfDomain::Vertex);
    auto points = std::make_shared<std::vector<glm::vec3>>();
    SdfQuery q;
    q.origin_offset = all.origin_offset;
    for (std::size_t i = 0; i < all.size(); i += 4099) {
      points->push_back(all.origins[i]);
      q.normals.push_back(all.normals[i]);
      q.valid.push_back(all.valid[i]);
    }
    q.origins = *points;
    q.origin_storage = points;
    return q;
  };
  backend.set_mesh(base);
  EXPECT_TRUE(backend.bvh().nodes.empty());
  backend.update_positions(moved.positions);
  EXPECT_EQ(backend.last_timings().front().stage, "bvh_build");
  const SdfQuery q = sample(moved);
  ASSERT_GT(q.size(), 100u);
  const RawSdf updated = backend.compute(q, {});
  backend.set_mesh(moved);
  const RawSdf fresh = backend.compute(q, {});
  EXPECT_EQ(updated.values, fresh.values);
  EXPECT_EQ(updated.kept_rays, fresh.kept_rays);
  // Rays across a sphere of radius ~1.02: chords between 0 and the diameter, none missing.
  for (std::size_t i = 0; i < q.size(); ++i) {
    EXPECT_GT(fresh.kept_rays[i], 0u) << i;
    EXPECT_GT(fresh.values[i], 0.5f) << i;
    EXPECT_LT(fresh.values[i], 2.1f) << i;
  }
}

INSTANTIATE_TEST_SUITE_P(Tracer, OpenClUpdate, ::testing::Values(test::Tracer::BvhBundles, test::Tracer::BvhSingle, test::Tracer::Octree),
                         [](const auto& p) { return std::string(test::tracer_name(p.param)); });

TEST(OpenClRobustness, SmallMemoryCapBatchesWithoutChangingResults) {
  SDFKIT_REQUIRE_CL(shared);
  cl::OpenClConfig config;
  config.device = std::to_string(shared.device().index);
  config.memory_cap = 100 * (2 * 16 + 30 * 8 + 8) + 5;  // 100 points of 30 rays per batch
  config.bvh_bundles = true;  // the shared backend's tracer (not the device's default: on a GPU, single rays)
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

// The skeleton with real SDF backends (the OpenCL ray caster on PoCL and the Embree reference):
// triangle soups with duplicate triangles and non-manifold edges are supported input, synthetic
// worms get their exact midline within 1 % of the length, every frame of the shared Sibernetic
// worm within 2 % with no head/tail swap, and its compression meets 20:1 at RMSE <= 1 %.
#include "analytic.hpp"
#include "device_policy.hpp"
#include "scratch.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/pointcloud/pointcloud.hpp"
#include "sdfkit/pointcloud/skinning.hpp"
#ifdef SDFKIT_POINTCLOUD_TEST_OPENCL
#include "sdfkit/opencl/opencl_backend.hpp"
#endif
#ifdef SDFKIT_POINTCLOUD_TEST_REFERENCE
#include "sdfkit/reference/embree_backend.hpp"
#endif

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <numbers>
#include <sstream>

namespace pc = sdfkit::pointcloud;

namespace {

sdfkit::SdfBackend* backend_named(const std::string& name) {
#ifdef SDFKIT_POINTCLOUD_TEST_OPENCL
  if (name == "opencl") {
    static const bool has = !sdfkit::cl::list_devices().empty();
    static std::unique_ptr<sdfkit::SdfBackend> b = has ? std::make_unique<sdfkit::cl::OpenClBackend>() : nullptr;
    return b.get();
  }
#endif
#ifdef SDFKIT_POINTCLOUD_TEST_REFERENCE
  if (name == "embree") {
    static std::unique_ptr<sdfkit::SdfBackend> b = std::make_unique<sdfkit::reference::EmbreeBackend>();
    return b.get();
  }
#endif
  return nullptr;
}

std::vector<std::string> backend_names() {
  std::vector<std::string> n;
#ifdef SDFKIT_POINTCLOUD_TEST_OPENCL
  n.push_back("opencl");
#endif
#ifdef SDFKIT_POINTCLOUD_TEST_REFERENCE
  n.push_back("embree");
#endif
  return n;
}

std::vector<glm::vec3> sphere_points(std::size_t n, float r) {
  std::vector<glm::vec3> p(n);
  const float golden = std::numbers::pi_v<float> * (3.0f - std::sqrt(5.0f));
  for (std::size_t i = 0; i < n; ++i) {
    const float y = 1.0f - 2.0f * (static_cast<float>(i) + 0.5f) / static_cast<float>(n);
    const float rad = std::sqrt(1.0f - y * y);
    p[i] = r * glm::vec3(std::cos(golden * i) * rad, y, std::sin(golden * i) * rad);
  }
  return p;
}

std::vector<pc::Polyline> read_midlines(const std::string& path) {
  std::ifstream in(path);
  std::vector<pc::Polyline> lines;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::size_t f;
    int slice;
    float x, y, z;
    if (!(ls >> f >> slice >> x >> y >> z)) continue;
    if (lines.size() <= f) lines.resize(f + 1);
    lines[f].nodes.push_back({{x, y, z}, 0.0f});
  }
  return lines;
}

const std::string kWorm = std::string(SDFKIT_SOURCE_DIR) + "/tests/data/worm";

}  // namespace

class PointcloudDevice : public ::testing::TestWithParam<std::string> {
protected:
  void SetUp() override {
    backend_ = backend_named(GetParam());
    if (!backend_) {
      if (sdfkit::test::allow_no_device()) GTEST_SKIP() << "no " << GetParam() << " device";
      FAIL() << "no " << GetParam() << " device (SDFKIT_ALLOW_NO_DEVICE=1 to skip)";
    }
  }
  sdfkit::SdfBackend* backend_ = nullptr;
};

TEST_P(PointcloudDevice, SoupWithDuplicateTrianglesAndNonManifoldEdgesIsSupported) {
  const float r = 2.0f;
  const auto pts = sphere_points(1200, r);
  const pc::Neighbours nb = pc::k_nearest(pts, pc::kDefaultNeighbours);
  const auto o = pc::orient_normals_mst(pts, pc::pca_normals(pts, nb), nb, 1);
  sdfkit::Mesh soup = pc::tangent_plane_surface(pts, o.normals, nb, false);
  const sdfkit::Mesh clean = pc::tangent_plane_surface(pts, o.normals, nb, true);
  ASSERT_GT(soup.triangles.size(), clean.triangles.size());  // duplicates present
  // A fin inside the sphere on an existing edge: that edge now has three (or more) triangles.
  const auto t0 = clean.triangles[0];
  soup.positions.push_back(0.999f * (pts[t0[0]] + pts[t0[1]]) * 0.5f - 0.001f * pts[t0[2]]);
  soup.triangles.push_back({t0[1], t0[0], static_cast<std::uint32_t>(soup.positions.size() - 1)});
  std::vector<glm::vec3> normals = o.normals;
  normals.push_back(glm::vec3(0.0f));  // the fin's vertex casts no ray
  sdfkit::SdfOptions opt;
  opt.rays = 16;
  const auto a = pc::point_sdf(*backend_, soup, normals, opt);
  const auto b = pc::point_sdf(*backend_, clean, o.normals, opt);
  const float expect = sdfkit::test::sphere_closed_form(r, opt);
  double mean = 0.0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    ASSERT_TRUE(std::isfinite(a[i]));
    EXPECT_NEAR(a[i], b[i], 0.02f * expect) << i;  // duplicates change no first hit
    mean += b[i];
  }
  mean /= static_cast<double>(pts.size());
  EXPECT_NEAR(mean, expect, 0.02 * expect);
}

TEST_P(PointcloudDevice, SyntheticWormsWithinOnePercentOfTheirLength) {
  for (int s = 0; s < 3; ++s) {
    pc::WormShape shape;
    shape.seed = static_cast<std::uint32_t>(s + 1);
    shape.phase = 1.1f * static_cast<float>(s);
    shape.waves = 0.6f + 0.4f * static_cast<float>(s);
    shape.noise = 0.1f;
    const pc::SyntheticWorm w = pc::synthetic_worm(shape);
    pc::SkeletonOptions opt;
    opt.segments = 12;
    const pc::SkeletonResult r = pc::point_cloud_skeleton(w.points, *backend_, opt);
    EXPECT_TRUE(r.exact);
    ASSERT_EQ(r.polyline.nodes.size(), 13u);
    EXPECT_LT(pc::mean_distance(r.polyline, w.midline, 0.25f), 0.01f * w.length) << "worm " << s;
    // The polyline spans the body (its ends within the tips' radius of the true ends).
    EXPECT_GT(r.polyline.length(), 0.85f * w.length);
    // Radii: half the SDF, near the tube's radius mid-body.
    EXPECT_NEAR(r.polyline.nodes[6].radius, shape.max_radius, 0.25f * shape.max_radius);
    // Step timings are all reported (no subsample step without max_points).
    EXPECT_EQ(r.times.size(), 8u);
    EXPECT_TRUE(r.sample.empty());
  }
}

TEST_P(PointcloudDevice, SubsampledLargeCloudKeepsItsMidline) {
  pc::WormShape shape;
  shape.points = 12000;
  const pc::SyntheticWorm w = pc::synthetic_worm(shape);
  pc::SkeletonOptions opt;
  opt.segments = 12;
  opt.max_points = 3000;
  const pc::SkeletonResult r = pc::point_cloud_skeleton(w.points, *backend_, opt);
  ASSERT_EQ(r.sample.size(), 3000u);
  EXPECT_TRUE(std::is_sorted(r.sample.begin(), r.sample.end()));
  EXPECT_EQ(r.sdf.size(), 3000u);
  EXPECT_EQ(r.times.front().step, "subsample");
  EXPECT_LT(pc::mean_distance(r.polyline, w.midline, 0.25f), 0.01f * w.length);
  opt.max_points = 10;
  EXPECT_THROW(pc::point_cloud_skeleton(w.points, *backend_, opt), sdfkit::InputError);
}

TEST_P(PointcloudDevice, EveryWormFrameWithinTwoPercentWithoutHeadTailSwap) {
  const pc::FrameSet set = pc::read_frames(kWorm, true);
  const auto mid = read_midlines(kWorm + "/midline.txt");
  ASSERT_EQ(mid.size(), set.frames.size());
  pc::SkeletonOptions opt;
  opt.segments = 16;
  const pc::SequenceSkeleton seq = pc::skeleton_sequence(set.frames, *backend_, opt, 33);
  EXPECT_TRUE(seq.inexact.empty());
  int first_end = 0;
  for (std::size_t f = 0; f < set.frames.size(); ++f) {
    const pc::Polyline& line = seq.frames[f].polyline;
    ASSERT_EQ(line.nodes.size(), 17u) << "frame " << f;
    ASSERT_EQ(seq.subdivided[f].nodes.size(), 33u);
    const float body = mid[f].length();
    EXPECT_LT(pc::mean_distance(line, mid[f], 0.25f), 0.02f * body) << "frame " << f;
    EXPECT_LT(pc::mean_distance(mid[f], line, 0.25f), 0.02f * body) << "frame " << f;
    // Which end of the simulator's midline the polyline starts at: the same in every frame.
    const glm::vec3 p0 = line.nodes.front().position;
    const int end = glm::distance(p0, mid[f].nodes.front().position) < glm::distance(p0, mid[f].nodes.back().position) ? 1 : -1;
    if (f == 0) first_end = end;
    EXPECT_EQ(end, first_end) << "head and tail swapped at frame " << f;
  }
}

// One backend suffices here (the CLI test runs the same on OpenCL): the reference when built.
TEST(PointcloudCompression, WormMeetsTwentyToOneAtOnePercent) {
  const auto names = backend_names();
  ASSERT_FALSE(names.empty());
  sdfkit::SdfBackend* backend_ = backend_named(names.back());
  if (!backend_) {
    if (sdfkit::test::allow_no_device()) GTEST_SKIP() << "no device";
    FAIL() << "no " << names.back() << " device (SDFKIT_ALLOW_NO_DEVICE=1 to skip)";
  }
  const pc::FrameSet shell = pc::read_frames(kWorm, true);
  const pc::FrameSet all = pc::read_frames(kWorm, false);
  pc::CompressionOptions opt;
  opt.bones = 16;
  opt.frame_time = all.frame_time;
  const pc::Compression c = pc::compress_animation(all.frames, shell.frames, *backend_, opt);
  // Weights: at most 4 bones, non-negative, summing to 1.
  for (const auto& w : c.animation.weights) {
    float s = 0.0f;
    for (float x : w) {
      EXPECT_GE(x, 0.0f);
      s += x;
    }
    EXPECT_NEAR(s, 1.0f, 1e-4f);
  }
  sdfkit::test::ScratchDir d;
  const std::size_t bytes = pc::write_skinned_glb(c.animation, d.path("worm.glb"));
  const auto played = pc::play_skinned_glb(d.path("worm.glb"));
  const auto mid = read_midlines(kWorm + "/midline.txt");
  const pc::CompressionReport r = pc::measure_compression(all.frames, played, bytes, 16, mid[0].length());
  EXPECT_GE(r.ratio, 20.0);
  EXPECT_LE(r.rmse_percent, 1.0);
  EXPECT_LT(r.kg_error, 5.0);
  EXPECT_GT(r.rmse, 0.0);
}

INSTANTIATE_TEST_SUITE_P(Backends, PointcloudDevice, ::testing::ValuesIn(backend_names()),
                         [](const auto& param_info) { return param_info.param; });

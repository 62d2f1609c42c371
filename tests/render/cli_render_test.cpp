// `sdfkit render`, `compare` and `smooth` end to end: the real binary on results written by the
// io library (analytic values) and by two different backends on a real mesh.
#include "analytic.hpp"

#include "sdfkit/core/shapes.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/io/field.hpp"

#include "run.hpp"

#include "sdfkit/pointcloud/skinning.hpp"
#include "scratch.hpp"

#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

namespace fs = std::filesystem;

namespace sdfkit {
namespace {

struct RunResult {
  int exit_code = -1;
  std::string out, err;
};

using sdfkit::test::slurp;

// The number printed after `label` on its line of `text`.
double number_after(const std::string& text, const std::string& label) {
  const std::size_t at = text.find(label);
  if (at == std::string::npos) return -1e30;
  return std::stod(text.substr(at + label.size()));
}

class RenderCli : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = scratch_.dir();
  }
  RunResult run(const std::string& args) {
    const auto r = sdfkit::test::run_command(std::string(SDFKIT_CLI) + " " + args, dir_);
    return {r.exit_code, r.out, r.err};
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // An icosphere as OFF, and a result on it with value 1 + y per vertex (or per face).
  io::Asset sphere_result(const std::string& name, SdfDomain domain) {
    const Mesh m = shapes::icosphere(1.0f, 2);
    std::ofstream off(path("sphere.off"));
    off << "OFF\n" << m.vertex_count() << " " << m.face_count() << " 0\n";
    for (const glm::vec3& p : m.positions) off << p.x << " " << p.y << " " << p.z << "\n";
    for (const Triangle& t : m.triangles) off << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
    off.close();
    const io::Asset a = io::load_asset(path("sphere.off"));
    SdfField f;
    f.domain = domain;
    const std::vector<glm::vec3> c = domain == SdfDomain::Vertex ? a.mesh.positions : face_centroids(a.mesh);
    for (const glm::vec3& p : c) f.values.push_back(1.0f + p.y);
    io::write_field(path(name), a, f);
    return a;
  }
  sdfkit::test::ScratchDir scratch_;  // unique per run: two trees may run the suite at once
  fs::path dir_;
};

bool is_png(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  char sig[8] = {};
  f.read(sig, 8);
  return std::string(sig + 1, 3) == "PNG";
}

TEST_F(RenderCli, RendersResultsPerVertexAndPerFace) {
  sphere_result("v.glb", SdfDomain::Vertex);
  RunResult r = run("render " + path("v.glb") + " -o " + path("v.png") + " --views 2 --width 200 --height 160");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(is_png(path("v.png")));
  sphere_result("f.ply", SdfDomain::Face);
  r = run("render " + path("f.ply") + " -o " + path("f.png") + " --views 1 --width 128 --height 128 --no-histogram");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("face values"), std::string::npos) << r.out;
  EXPECT_TRUE(is_png(path("f.png")));
  // A skeleton overlay; a broken skeleton is one error line.
  std::ofstream(path("s.json")) << R"({"nodes":[{"position":[0,-0.5,0],"radius":0.5},{"position":[0,0.5,0]}],"edges":[[0,1]]})";
  r = run("render " + path("v.glb") + " -o " + path("s.png") + " --views 1 --width 128 --height 128 --skeleton " +
          path("s.json"));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::ofstream(path("bad.json")) << R"({"nodes":[{"position":[0,0,0]}],"edges":[[0,7]]})";
  r = run("render " + path("v.glb") + " -o " + path("b.png") + " --skeleton " + path("bad.json"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("b.png")));
}

TEST_F(RenderCli, CompareWithItselfIsExact) {
  sphere_result("v.glb", SdfDomain::Vertex);
  sphere_result("v.txt", SdfDomain::Vertex);
  RunResult r = run("compare " + path("v.glb") + " " + path("v.glb") + " -o " + path("d.png") +
                    " --views 1 --width 128 --height 128");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_DOUBLE_EQ(number_after(r.out, "pearson"), 1.0) << r.out;
  EXPECT_DOUBLE_EQ(number_after(r.out, "median relative |a-b|/|b|"), 0.0) << r.out;
  EXPECT_DOUBLE_EQ(number_after(r.out, "95th percentile relative"), 0.0) << r.out;
  EXPECT_DOUBLE_EQ(number_after(r.out, "median signed difference a-b"), 0.0) << r.out;
  EXPECT_TRUE(is_png(path("d.png")));
  // A .txt against the glb on the same mesh, and against a mesh with other counts.
  r = run("compare " + path("v.txt") + " " + path("v.glb"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_DOUBLE_EQ(number_after(r.out, "pearson"), 1.0) << r.out;
  r = run("compare " + path("v.txt") + " " + path("v.txt") + " --mesh " + test::data_mesh("cow.off"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  sphere_result("f.ply", SdfDomain::Face);
  r = run("compare " + path("v.glb") + " " + path("f.ply"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("not results on the same mesh"), std::string::npos) << r.err;
}

TEST_F(RenderCli, SmoothKeepsTheMeshAndFlattensTheField) {
  const io::Asset a = sphere_result("v.ply", SdfDomain::Vertex);
  const RunResult r = run("smooth " + path("v.ply") + " -o " + path("s.glb") + " --rings 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::FieldFile in = io::read_field(path("v.ply")), out = io::read_field(path("s.glb"));
  ASSERT_EQ(out.values.size(), in.values.size());
  const auto [lo_in, hi_in] = std::minmax_element(in.values.begin(), in.values.end());
  const auto [lo_out, hi_out] = std::minmax_element(out.values.begin(), out.values.end());
  EXPECT_GT(*lo_out, *lo_in);  // averaging pulls the extremes in
  EXPECT_LT(*hi_out, *hi_in);
}

// Two backends on a real mesh agree the way the paper's Figure 9 shows: high correlation and a
// small median difference.
TEST_F(RenderCli, CompareTwoBackendsOnARealMesh) {
  if (!SDFKIT_TEST_HAS_OPENCL) GTEST_SKIP() << "built without OpenCL";
  const std::string cow = test::data_mesh("cow.off");
  RunResult r = run("compute " + cow + " -o " + path("vk.glb") + " --backend vulkan --views 64 --resolution 256 -q");  // seconds on lavapipe
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run("compute " + cow + " -o " + path("cl.ply") + " --backend opencl -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run("compare " + path("cl.ply") + " " + path("vk.glb"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(number_after(r.out, "pearson"), 0.95) << r.out;
  EXPECT_LT(number_after(r.out, "median relative |a-b|/|b|"), 5.0) << r.out;  // percent
  EXPECT_LT(std::abs(number_after(r.out, "median signed relative (a-b)/|b|")), 2.0) << r.out;
  EXPECT_NE(r.out.find(">= 5.00%"), std::string::npos) << r.out;
}


// ---- Point clouds and skeleton pictures (issues 11 and 14) ---------------------------------------

// Pixels of one exact colour in columns [x0, x1) of a PNG; -1 when it cannot be read.
struct Png {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
  explicit Png(const std::string& path) {
    int c = 0;
    std::uint8_t* data = stbi_load(path.c_str(), &width, &height, &c, 4);
    if (data) rgba.assign(data, data + static_cast<std::size_t>(width) * height * 4);
    stbi_image_free(data);
  }
  std::size_t count(std::array<std::uint8_t, 3> c, int x0, int x1) const {
    std::size_t n = 0;
    for (int y = 0; y < height; ++y)
      for (int x = x0; x < x1; ++x) {
        const std::uint8_t* p = &rgba[4 * (static_cast<std::size_t>(y) * width + x)];
        n += p[0] == c[0] && p[1] == c[1] && p[2] == c[2];
      }
    return n;
  }
};
constexpr std::array<std::uint8_t, 3> kFirst{200, 0, 200};  // render::skeleton_color(First)
constexpr std::array<std::uint8_t, 3> kLeaf{0, 170, 0};      // render::skeleton_color(Leaf)

// A bent tube of points along x (frame k bends the other way as k grows), and its polyline.
std::vector<glm::vec3> tube_points(int k) {
  std::vector<glm::vec3> p;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 12; ++j) {
      const float t = static_cast<float>(i) / 39.0f, a = static_cast<float>(j) * std::numbers::pi_v<float> / 6.0f;
      p.emplace_back(30.0f * t, std::cos(a), (2.0f - static_cast<float>(k)) * std::sin(std::numbers::pi_v<float> * t) +
                                                std::sin(a));
    }
  return p;
}
std::string polyline_json(int k) {
  std::string s = "{\"nodes\":[";
  for (int n = 0; n <= 4; ++n) {
    const float t = static_cast<float>(n) / 4.0f;
    s += (n ? "," : "") + std::string("{\"position\":[") + std::to_string(30.0f * t) + ",0," +
         std::to_string((2.0f - static_cast<float>(k)) * std::sin(std::numbers::pi_v<float> * t)) + "],\"radius\":1}";
  }
  return s + "]}";
}

TEST_F(RenderCli, PointCloudFrameAndStripWithTheirSkeletons) {
  fs::create_directories(path("frames"));
  std::string frames_json = "{\"frames\":[";
  for (int k = 0; k < 5; ++k) {
    std::ofstream xyz(path("frames/f" + std::to_string(k) + ".xyz"));
    for (const glm::vec3& p : tube_points(k)) xyz << p.x << " " << p.y << " " << p.z << "\n";
    frames_json += (k ? "," : "") + polyline_json(k);
  }
  std::ofstream(path("frames.json")) << frames_json << "]}";
  std::ofstream(path("one.json")) << polyline_json(0);

  // One frame (a single .xyz file) with its polyline: points, curve, first node and last leaf.
  RunResult r = run("render " + path("frames/f0.xyz") + " --skeleton " + path("one.json") + " -o " + path("one.png") +
                    " --width 200 --height 300");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Png one(path("one.png"));
  ASSERT_EQ(one.width, 200);
  EXPECT_NEAR(static_cast<double>(one.count(kFirst, 0, 200)), 144.0, 20.0);
  EXPECT_NEAR(static_cast<double>(one.count(kLeaf, 0, 200)), 100.0, 15.0);

  // The directory as a strip of 3 frames (0, 2, 4): one first-node marker in each panel.
  r = run("render " + path("frames") + " --skeleton " + path("frames.json") + " --strip 3 -o " + path("strip.png") +
          " --width 300 --height 240");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("3 of 5 frames"), std::string::npos) << r.out;
  const Png strip(path("strip.png"));
  ASSERT_EQ(strip.width, 300);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(static_cast<double>(strip.count(kFirst, i * 100 + 1, (i + 1) * 100)), 144.0, 20.0) << "panel " << i;

  // --frame picks the skeleton's frame too.
  r = run("render " + path("frames") + " --skeleton " + path("frames.json") + " --frame 3 -o " + path("f3.png") +
          " --width 200 --height 300");
  EXPECT_EQ(r.exit_code, 0) << r.err;

  // Usage errors (exit 2) and bad input (exit 1): one line each, no picture written.
  const auto fails = [&](const std::string& args, int code, const std::string& says) {
    const RunResult f = run("render " + args + " -o " + path("bad.png"));
    EXPECT_EQ(f.exit_code, code) << args << "\n" << f.err;
    EXPECT_EQ(std::count(f.err.begin(), f.err.end(), '\n'), 1) << args << "\n" << f.err;
    EXPECT_NE(f.err.find(says), std::string::npos) << args << "\n" << f.err;
    EXPECT_FALSE(fs::exists(path("bad.png"))) << args;
  };
  fails(path("frames") + " --strip 6", 1, "fewer than --strip 6");
  fails(path("frames") + " --frame 5", 1, "--frame 5 does not exist");
  fails(path("frames") + " --skeleton " + path("one.json") + " --strip 2", 1, "1 frames of skeletons");
  fails(path("frames/f0.xyz") + " --skeleton " + path("frames.json"), 1, "5 frames of skeletons");
  fails(path("frames") + " --strip 2 --views 2", 2, "--views");
  fails(path("frames") + " --strip 2 --frame 1", 2, "leave out --frame");
  fails(path("frames") + " --range 0 1", 2, "do not apply to a point cloud");
  fails(path("frames") + " --backend opencl", 2, "--backend does not apply");
  fails(path("frames") + " --up w", 2, "--up");
  fails("builtin:sphere --strip 2", 2, "--strip and --frame need a point cloud");
  fails(path("missing") + " --strip 2", 1, "no such file or directory");
  std::ofstream(path("mesh.off")) << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  fails(path("mesh.off") + " --points", 2, "is a mesh file");
  std::ofstream(path("broken.json")) << R"({"frames":[{"nodes":[{"position":[0,0,0]}],"edges":[[0,4]]}]})";
  fails(path("frames/f1.xyz") + " --skeleton " + path("broken.json"), 1, "does not exist");
  std::ofstream(path("garbage.xyz")) << "1 2 3\nnot numbers at all\n";
  const RunResult g = run("render " + path("garbage.xyz") + " -o " + path("bad.png"));
  EXPECT_EQ(g.exit_code, 1) << g.err;
  EXPECT_EQ(std::count(g.err.begin(), g.err.end(), '\n'), 1) << g.err;
  EXPECT_FALSE(fs::exists(path("bad.png")));
}

// The shared worm (a Sibernetic frame set) as a strip, and a skinned point animation as
// compress-animation writes it, played back and drawn frame by frame.
TEST_F(RenderCli, SiberneticFramesAndAPlayedBackAnimation) {
  const std::string worm = std::string(SDFKIT_SOURCE_DIR) + "/tests/data/worm";
  RunResult r = run("render " + worm + " --strip 4 -o " + path("worm.png") + " --width 400 --height 300");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("4 of 100 frames, 1421 points"), std::string::npos) << r.out;
  const Png png(path("worm.png"));
  ASSERT_EQ(png.width, 400);

  // 4 bones translated together by (0, 0, f) in frame f: the played-back frames are the rest
  // points moved by f, so frame 3's panel is the same picture as frame 0's (each centred).
  pointcloud::SkinnedAnimation a;
  a.frame_time = 0.1;
  for (const glm::vec3& p : tube_points(2)) {
    a.rest.push_back(p);
    a.joints.push_back({0, 1, 2, 3});
    a.weights.push_back({0.25f, 0.25f, 0.25f, 0.25f});
  }
  for (int f = 0; f < 4; ++f) {
    std::vector<pointcloud::BonePose> bones(4);
    for (auto& b : bones) b.translation = glm::vec3(0.0f, 0.0f, static_cast<float>(f));
    a.poses.push_back(bones);
  }
  a.inverse_bind.assign(4, glm::mat4(1.0f));
  pointcloud::write_skinned_glb(a, path("anim.glb"));
  r = run("render " + path("anim.glb") + " --strip 4 -o " + path("anim.png") + " --width 400 --height 300");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("4 of 4 frames, 480 points"), std::string::npos) << r.out;
  const Png anim(path("anim.png"));
  ASSERT_EQ(anim.width, 400);
  // Panels 0 and 3 show the same points (moved along the view's horizontal, each panel centred
  // on its frame): the same number of drawn pixels and the same box, up to sub-pixel placement.
  std::array<std::size_t, 4> drawn{};
  std::array<std::array<int, 4>, 4> box{};
  for (int i = 0; i < 4; ++i) {
    box[i] = {400, 300, 0, 0};
    for (int y = 0; y < 260; ++y)
      for (int x = i * 100 + 1; x < (i + 1) * 100; ++x)
        if (anim.rgba[4 * (static_cast<std::size_t>(y) * 400 + x)] != 255) {
          ++drawn[i];
          box[i] = {std::min(box[i][0], x - i * 100), std::min(box[i][1], y), std::max(box[i][2], x - i * 100),
                    std::max(box[i][3], y)};
        }
  }
  EXPECT_GT(drawn[0], 500u);
  EXPECT_NEAR(static_cast<double>(drawn[3]), static_cast<double>(drawn[0]), 0.05 * drawn[0]);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(box[3][k], box[0][k], 1) << k;
}

// A mesh with its skeleton: the long axis drawn up by default, --up overrides it; the skeleton's
// leaves in their colour.
TEST_F(RenderCli, MeshSkeletonPictureStandsAndShowsLeaves) {
  const Mesh m = shapes::box(1.0f, 1.0f, 6.0f, 2);  // long along z
  std::ofstream off(path("bar.off"));
  off << "OFF\n" << m.vertex_count() << " " << m.face_count() << " 0\n";
  for (const glm::vec3& p : m.positions) off << p.x << " " << p.y << " " << p.z << "\n";
  for (const Triangle& t : m.triangles) off << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
  off.close();
  std::ofstream(path("bar.json")) << R"({"nodes":[{"position":[0,0,-2.5]},{"position":[0,0,0]},{"position":[0,0,2.5]}],"edges":[[0,1],[1,2]],"sheet_triangles":[]})";
  const auto leaf_box = [&](const std::string& png) {
    const Png p(png);
    int x0 = p.width, x1 = 0, y0 = p.height, y1 = 0;
    for (int y = 0; y < p.height; ++y)
      for (int x = 0; x < p.width; ++x) {
        const std::uint8_t* q = &p.rgba[4 * (static_cast<std::size_t>(y) * p.width + x)];
        if (q[0] == kLeaf[0] && q[1] == kLeaf[1] && q[2] == kLeaf[2]) {
          x0 = std::min(x0, x);
          x1 = std::max(x1, x);
          y0 = std::min(y0, y);
          y1 = std::max(y1, y);
        }
      }
    return std::array<int, 4>{x0, y0, x1, y1};
  };
  RunResult r = run("render " + path("bar.off") + " --skeleton " + path("bar.json") + " --views 1 --no-histogram " +
                    "--no-colorbar --width 200 --height 200 -o " + path("up.png"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::array<int, 4> b = leaf_box(path("up.png"));
  EXPECT_GT(b[3] - b[1], 120);  // the two leaves far apart vertically: the bar stands
  EXPECT_LT(b[2] - b[0], 30);
  r = run("render " + path("bar.off") + " --skeleton " + path("bar.json") + " --views 1 --no-histogram " +
          "--no-colorbar --width 200 --height 200 --up y -o " + path("lying.png"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  b = leaf_box(path("lying.png"));
  EXPECT_GT(b[2] - b[0], 80);  // with y up the bar lies across the picture
  EXPECT_LT(b[3] - b[1], 60);
}

}  // namespace
}  // namespace sdfkit

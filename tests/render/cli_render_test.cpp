// `sdfkit render`, `compare` and `smooth` end to end: the real binary on results written by the
// io library (analytic values) and by two different backends on a real mesh.
#include "analytic.hpp"

#include "sdfkit/core/shapes.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/io/field.hpp"

#include "run.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
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
    dir_ = fs::temp_directory_path() /
           ("sdfkit_render_cli_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
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

}  // namespace
}  // namespace sdfkit

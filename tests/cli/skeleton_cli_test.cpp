// `sdfkit skeleton` end to end on PoCL (auto picks it for skeletons): a capsule's skeleton is one
// curve along its axis, the glb output carries the skeleton as its own node and reads back as
// the surface alone, and an open mesh is one clean error.
#include "analytic.hpp"
#include "scratch.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace fs = std::filesystem;

namespace {
int run(const std::string& args, const fs::path& log) {
  const int status = std::system((std::string(SDFKIT_CLI) + " " + args + " >" + log.string() + " 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
}  // namespace

TEST(SkeletonCli, CapsuleGivesOneCurveAlongItsAxis) {
  const sdfkit::test::ScratchDir scratch;  // unique per run: two trees may run the suite at once
  const fs::path dir = scratch.dir();
  fs::remove_all(dir);
  fs::create_directories(dir);
  // --backend auto (the default) picks the OpenCL ray caster for skeletons when it has a device.
  ASSERT_EQ(run("skeleton builtin:capsule -o " + (dir / "s.json").string() + " --rays 12", dir / "log"), 0);
  {
    std::ifstream log(dir / "log");
    const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("with the opencl SDF"), std::string::npos) << text;
  }
  std::ifstream f(dir / "s.json");
  const auto j = nlohmann::json::parse(f);
  const auto& nodes = j.at("nodes");
  ASSERT_GE(nodes.size(), 2u);
  EXPECT_EQ(j.at("sheet_triangles").size(), 0u);
  EXPECT_EQ(j.at("edges").size(), nodes.size() - 1);  // a path: one curve, no cycle
  // builtin:capsule: radius 0.5, cylinder length 3 along z (total length 4).
  std::size_t vertices = 0;
  for (const auto& n : nodes) {
    const auto p = n.at("position");
    EXPECT_LT(std::hypot(p[0].get<double>(), p[1].get<double>()), 0.02 * 4.0);
    vertices += n.at("vertices").size();
  }
  EXPECT_GT(vertices, 0u);
  fs::remove_all(dir);
}

TEST(SkeletonCli, GlbCarriesTheSkeletonAndOpenMeshesAreRefused) {
  const sdfkit::test::ScratchDir scratch;  // unique per run: two trees may run the suite at once
  const fs::path dir = scratch.dir();
  fs::remove_all(dir);
  fs::create_directories(dir);
  ASSERT_EQ(run("skeleton builtin:torus -o " + (dir / "t.glb").string() + " --backend opencl --rays 12", dir / "log"), 0);
  ASSERT_EQ(run("info " + (dir / "t.glb").string() + " --json", dir / "info"), 0);
  std::ifstream info(dir / "info");
  std::string text((std::istreambuf_iterator<char>(info)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("skipped 1 sdfkit overlays (skeleton)"), std::string::npos) << text;
  EXPECT_EQ(run("skeleton " + sdfkit::test::data_mesh("cube-ouvert.off") + " -o " + (dir / "x.json").string() +
                    " --backend opencl",
                dir / "log2"),
            1);
  EXPECT_FALSE(fs::exists(dir / "x.json"));
  fs::remove_all(dir);
}

// One road for every command, on the real executable with both backends (lavapipe and PoCL in
// CI): the backend contract (an option the chosen backend would ignore is a usage error naming
// the backend that uses it), the automatic choice and its reason, exit code 2 for every usage
// error of every subcommand, and a batch rerun that recomputes when any option changed.
#include "analytic.hpp"
#include "run.hpp"
#include "scratch.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>

namespace fs = std::filesystem;

namespace {

using RunResult = sdfkit::test::CommandResult;

class Road : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = scratch_.dir();
  }
  RunResult run(const std::string& args) { return sdfkit::test::run_command(std::string(SDFKIT_CLI) + " " + args, dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  nlohmann::json json(const std::string& name) const {
    std::ifstream f(dir_ / name);
    return nlohmann::json::parse(f);
  }
  // A usage error: exit 2, one "sdfkit: ..." line (CLI11's own messages may take two) naming `what`.
  void expect_usage_error(const std::string& args, const std::string& what) {
    const RunResult r = run(args);
    EXPECT_FALSE(r.signaled) << args;
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << args << ": " << r.err;
  }
  sdfkit::test::ScratchDir scratch_;  // unique per run: two trees may run the suite at once
  fs::path dir_;
};

}  // namespace

TEST_F(Road, AnOptionTheBackendWouldIgnoreIsAUsageErrorNamingTheBackendThatUsesIt) {
  // Before: --rays on Vulkan was read by nothing, the output byte-identical to --rays 30.
  expect_usage_error("compute builtin:sphere -o " + path("a.txt") + " --backend vulkan --rays 4",
                     "--rays is an option of the opencl backend");
  expect_usage_error("compute builtin:sphere -o " + path("a.txt") + " --backend opencl --views 64",
                     "--views is an option of the vulkan backend");
  expect_usage_error("compute builtin:sphere -o " + path("a.txt") + " --backend opencl --peel-mode layers",
                     "the vulkan backend");
  expect_usage_error("compute builtin:sphere -o " + path("a.txt") + " --backend vulkan --accel octree",
                     "the opencl backend");
  expect_usage_error("compute builtin:sphere -o " + path("a.txt") + " --rays 4 --views 64", "both backends");
  // The other commands go the same road.
  expect_usage_error("skeleton builtin:capsule -o " + path("s.json") + " --backend vulkan --rays 8", "--rays");
  expect_usage_error("render builtin:capsule -o " + path("r.png") + " --backend vulkan --rays 8", "--rays");
  expect_usage_error("batch builtin:sphere --out " + path("out") + " --backend opencl --resolution 64", "--resolution");
  EXPECT_FALSE(fs::exists(dir_ / "a.txt"));
  EXPECT_FALSE(fs::exists(dir_ / "s.json"));
  EXPECT_FALSE(fs::exists(dir_ / "r.png"));
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

TEST_F(Road, AutoPicksOpenClOverACpuRasterizerAndSaysWhy) {
  const RunResult r = run("compute builtin:sphere -o " + path("a.txt") + " --json " + path("a.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = json("a.json");
  EXPECT_EQ(j.at("backend"), "opencl") << j.dump(2);
  const std::string why = j.at("backend_choice");
  EXPECT_NE(why.find("the only Vulkan device is a CPU rasterizer"), std::string::npos) << why;
  EXPECT_NE(r.out.find("backend opencl on "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("CPU rasterizer"), std::string::npos) << r.out;
  EXPECT_EQ(j.at("options").at("sdf").at("rays"), 30);
  // A Vulkan option narrows auto to Vulkan, and says so.
  const RunResult v = run("compute builtin:sphere -o " + path("b.txt") + " --views 16 --resolution 64 --json " + path("b.json"));
  ASSERT_EQ(v.exit_code, 0) << v.err;
  EXPECT_EQ(json("b.json").at("backend"), "vulkan");
  EXPECT_NE(json("b.json").at("backend_choice").get<std::string>().find("--views"), std::string::npos);
  // `sdfkit devices` shows the same choice.
  const RunResult d = run("devices");
  ASSERT_EQ(d.exit_code, 0) << d.err;
  EXPECT_NE(d.out.find("auto    -> opencl: "), std::string::npos) << d.out;
  EXPECT_NE(d.out.find("CPU rasterizer"), std::string::npos) << d.out;
}

TEST_F(Road, RenderComputesThroughThePipelineAndReportsItsChoice) {
  const RunResult r = run("render builtin:capsule -o " + path("r.png") + " --width 128 --height 96 --views 1 --rays 6");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("backend opencl on "), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(dir_ / "r.png"));
}

TEST_F(Road, TheSkeletonSaysWhatItsPerIterationRayCountDoesOnEachBackend) {
  // Before, the 4 rays per later iteration were silently ignored on Vulkan.
  const RunResult v = run("skeleton builtin:capsule -o " + path("v.json") +
                          " --backend vulkan --views 16 --resolution 64 --iterations 2 --proxy-vertices 300");
  ASSERT_EQ(v.exit_code, 0) << v.err;
  EXPECT_NE(v.out.find("the vulkan backend casts no rays, so the 4 rays per later iteration"), std::string::npos) << v.out;
  const RunResult c = run("skeleton builtin:capsule -o " + path("c.json") + " --rays 12 --iterations 2 --proxy-vertices 300");
  ASSERT_EQ(c.exit_code, 0) << c.err;
  EXPECT_NE(c.out.find("with the opencl SDF"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("SDF with 12 rays per point, then 4 per later iteration"), std::string::npos) << c.out;
}

TEST_F(Road, EveryUsageErrorExitsTwo) {
  const std::string mesh = sdfkit::test::data_mesh("cube-ouvert.off");
  const std::map<std::string, std::string> cases{
      {"info " + mesh + " --no-such-option", "--no-such-option"},
      {"info", "MESH"},
      {"compute builtin:sphere -o x.txt --rays 0", "--rays"},
      {"compute builtin:sphere -o x.txt --backend metal", "--backend"},
      {"devices extra", "extra"},
      {"batch " + mesh + " --out o --shard 2/2", "--shard"},
      {"batch " + mesh + " --out o --shard x", "--shard"},
      {"batch " + mesh + " --out o --jobs 0", "--jobs"},
      {"skeleton builtin:capsule -o s.txt", "skeleton output extension"},
      {"skeleton builtin:capsule -o s.json --per face", "per-vertex"},
      {"smooth " + mesh + " -o x.txt --rings 0", "--rings"},
      {"compare a.txt b.txt --limit 0", "--limit"},
      {"render builtin:capsule -o r.jpg", "PNG"},
      {"render builtin:capsule -o r.png --range 2 1", "--range"},
      {"no-such-command", "subcommand"},
  };
  for (const auto& [args, what] : cases) expect_usage_error(args, what);
  // `sdfkit bench` runs sdfkit-bench beside it, when the benchmarks were built.
  if (fs::exists(fs::path(SDFKIT_CLI).parent_path() / "bench" / "sdfkit-bench"))
    expect_usage_error("bench --no-such-option", "--no-such-option");
}

TEST_F(Road, ABatchRerunWithAnyOtherOptionRecomputes) {
  fs::create_directories(dir_ / "in");
  fs::copy_file(sdfkit::test::data_mesh("cube-ouvert.off"), dir_ / "in" / "cube.off");
  const auto status = [&](const std::string& options) {
    const RunResult r = run("batch " + path("in") + " --out " + path("out") + " --format txt " + options);
    EXPECT_EQ(r.exit_code, 0) << options << ": " << r.err;
    return json("out/batch-report.json").at("assets").at(0).at("status").get<std::string>();
  };
  // Before: the fingerprint listed options by hand and missed --accel and --peel-mode.
  const std::string cl = "--backend opencl --rays 6";
  EXPECT_EQ(status(cl), "done");
  EXPECT_EQ(status(cl), "skipped");
  EXPECT_EQ(status(cl + " --accel octree"), "done");
  EXPECT_EQ(status(cl + " --accel octree"), "skipped");
  EXPECT_EQ(status(cl + " --accel octree --memory-cap 1000000"), "done");
  const std::string vk = "--backend vulkan --views 16 --resolution 64";
  EXPECT_EQ(status(vk), "done");
  EXPECT_EQ(status(vk + " --peel-mode layers"), "done");
  EXPECT_EQ(status(vk + " --peel-mode layers"), "skipped");
  // The record holds the options it was made with.
  EXPECT_EQ(json("out/cube.json").at("options").at("backend").at("peel_mode"), "layers");
}

// Runs the real `sdfkit` binary on real and broken files: every bad input must give exactly one
// error line naming the file and a non-zero exit, never a crash, and never a written output.
#include "analytic.hpp"
#include "run.hpp"
#include "scratch.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;

namespace {

using RunResult = sdfkit::test::CommandResult;
using sdfkit::test::slurp;

class Cli : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = scratch_.dir();
  }

  RunResult run(const std::string& args) {
    return sdfkit::test::run_command(std::string(SDFKIT_CLI) + " " + args, dir_);
  }
  fs::path write(const std::string& name, const std::string& content) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << content;
    return p;
  }
  // One line on stderr, "sdfkit: error: ..." naming `what`, exit code 1.
  void expect_clean_error(const RunResult& r, const std::string& what) {
    EXPECT_FALSE(r.signaled) << r.err;
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("sdfkit: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
  }
  sdfkit::test::ScratchDir scratch_;  // unique per run: two trees may run the suite at once
  fs::path dir_;
};

}  // namespace

TEST_F(Cli, Version) {
  const RunResult r = run("--version");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("sdfkit "), std::string::npos);
}

TEST_F(Cli, InfoOnARealMesh) {
  const RunResult r = run("info " + sdfkit::test::data_mesh("cow.off"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("vertices:           2904"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("faces:              5804"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("boundary edges:     0"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("components:         1"), std::string::npos) << r.out;
}

TEST_F(Cli, InfoLoadOnlyGivesTheCountsAndTheLoadStages) {
  // --load-only skips the topology (no "components") and reports the read and weld times (the
  // cow has one duplicate vertex).
  const RunResult r = run("info --load-only --json " + sdfkit::test::data_mesh("cow.off"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"vertices\": 2904"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"welded_vertices\": 2903"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"read\": "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"weld\": "), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("components"), std::string::npos) << r.out;
  const RunResult text = run("info --load-only " + sdfkit::test::data_mesh("cow.off"));
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("weld:"), std::string::npos) << text.out;
  EXPECT_EQ(text.out.find("components"), std::string::npos) << text.out;
}

TEST_F(Cli, InfoReportsAnOpenMesh) {
  const RunResult r = run("info " + sdfkit::test::data_mesh("cube-ouvert.off") + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"closed\": false"), std::string::npos) << r.out;
}

// CGAL's boeing mixes windings (1432 of its 2564 faces wound against the rest): the load winds
// it outward, says so in one warning line, and info counts the flipped faces; the cow is wound
// right and nothing is flipped.
TEST_F(Cli, InfoCountsTheFacesTheLoadFlipped) {
  const RunResult r = run("info --json " + sdfkit::test::data_mesh("boeing.off"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"flipped_faces\": 1432"), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("flipped 1432 faces"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("mixed windings"), std::string::npos) << r.err;
  const RunResult cow = run("info " + sdfkit::test::data_mesh("cow.off"));
  ASSERT_EQ(cow.exit_code, 0) << cow.err;
  EXPECT_NE(cow.out.find("flipped faces:      0"), std::string::npos) << cow.out;
  EXPECT_EQ(cow.err.find("flipped"), std::string::npos) << cow.err;
}

TEST_F(Cli, InfoOnBuiltinShape) {
  const RunResult r = run("info builtin:torus");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("boundary edges:     0"), std::string::npos) << r.out;
}

TEST_F(Cli, MissingFile) { expect_clean_error(run("info " + (dir_ / "nope.off").string()), "nope.off"); }

TEST_F(Cli, UnknownExtension) {
  const fs::path p = write("mesh.xyz", "hello");
  expect_clean_error(run("info " + p.string()), "mesh.xyz");
}

TEST_F(Cli, TruncatedOff) {
  const fs::path p = write("t.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n");
  expect_clean_error(run("info " + p.string()), "t.off");
}

TEST_F(Cli, NaNCoordinates) {
  const fs::path p = write("nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n");
  expect_clean_error(run("info " + p.string()), "nan.off");
}

TEST_F(Cli, IndexOutOfRange) {
  const fs::path p = write("idx.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
  expect_clean_error(run("info " + p.string()), "idx.obj");
}

TEST_F(Cli, EmptyMesh) {
  const fs::path p = write("empty.off", "OFF\n0 0 0\n");
  expect_clean_error(run("info " + p.string()), "empty.off");
}

TEST_F(Cli, MalformedGlb) {
  const fs::path p = write("bad.glb", std::string("glTF\x02\x00\x00\x00garbage", 16));
  expect_clean_error(run("info " + p.string()), "bad.glb");
}

TEST_F(Cli, MalformedPly) {
  const fs::path p = write("bad.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n");
  expect_clean_error(run("info " + p.string()), "bad.ply");
}

TEST_F(Cli, FailedComputeWritesNothingAndKeepsAnExistingFile) {
  const fs::path bad = write("bad.off", "OFF\n3 1 0\n0 0 0\n");
  const fs::path out = write("result.txt", "previous result\n");
  expect_clean_error(run("compute " + bad.string() + " -o " + out.string()), "bad.off");
  EXPECT_EQ(slurp(out), "previous result\n");
  int files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_)) ++files;
  EXPECT_EQ(files, 4);  // bad.off, result.txt, stdout.txt, stderr.txt: no temporary left over
}

TEST_F(Cli, BadOptionValuesAreUsageErrors) {
  // A negative proxy size must not wrap around to a huge unsigned value and run.
  for (const char* cmd : {"compute builtin:sphere -o x.txt --rays 0", "skeleton builtin:capsule -o s.json --proxy-vertices -5"}) {
    const RunResult r = run(cmd);
    EXPECT_FALSE(r.signaled) << cmd;
    EXPECT_EQ(r.exit_code, 2) << cmd << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "s.json"));
  EXPECT_EQ(run("--help").exit_code, 0);
}

TEST_F(Cli, AnUnwritableOutputIsReportedBeforeAnyDeviceIsOpened) {
  // No device matches "no-such-device": had the device been opened first, that would be the error.
  // An output that cannot hold the values is a usage error (exit 2), as an unknown option is.
  const auto expect_usage_error = [](const RunResult& r, const std::string& what) {
    EXPECT_FALSE(r.signaled) << r.err;
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("sdfkit: usage error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
  };
  for (const char* out : {"x.off", "x.obj", "x.xyz"})
    expect_usage_error(run("compute builtin:sphere -o " + (dir_ / out).string() + " --device no-such-device"), out);
  expect_usage_error(run("compute builtin:sphere --per face -o " + (dir_ / "x.glb").string() +
                         " --device no-such-device"),
                     "per-face values cannot be stored in glTF");
  EXPECT_FALSE(fs::exists(dir_ / "x.off"));
}

TEST_F(Cli, CommandsRefuseOptionsTheyWouldIgnore) {
  // Skeletons and renders do not smooth; render's own --views is its figure's.
  for (const char* cmd : {"skeleton builtin:capsule -o s.json --smooth 2", "render builtin:capsule -o r.png --smooth 2",
                          "render builtin:capsule -o r.png --normalize"}) {
    const RunResult r = run(cmd);
    EXPECT_FALSE(r.signaled) << cmd;
    EXPECT_EQ(r.exit_code, 2) << cmd << ": " << r.err;  // a usage error
  }
}

TEST_F(Cli, UnknownBuiltin) { expect_clean_error(run("info builtin:teapot"), "builtin:teapot"); }

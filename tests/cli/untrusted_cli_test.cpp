// The sdfkit executable on hostile assets (SECURITY.md): a glTF reaching outside its directory
// is refused with one error line naming the asset and the URI, exit 1, no output written;
// --allow-external-paths lifts it; --max-triangles / --max-file-size refuse big assets.
// No device is needed: every refusal comes before a backend is opened.
#include "analytic.hpp"
#include "run.hpp"
#include "untrusted_fixture.hpp"
#include "scratch.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

namespace fs = std::filesystem;

namespace {

class UntrustedCli : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = scratch_.dir();
    h_ = sdfkit::test::make_hostile_assets(dir_);
  }

  sdfkit::test::CommandResult run(const std::string& args) {
    return sdfkit::test::run_command(std::string(SDFKIT_CLI) + " " + args, dir_);
  }
  static void expect_clean_error(const sdfkit::test::CommandResult& r, const std::string& what) {
    EXPECT_FALSE(r.signaled) << r.err;
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("sdfkit: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
  }
  std::size_t files_in(const fs::path& d) {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(d), fs::directory_iterator()));
  }

  sdfkit::test::ScratchDir scratch_;  // unique per run: two trees may run the suite at once
  fs::path dir_;
  sdfkit::test::HostileAssets h_;
};

}  // namespace

TEST_F(UntrustedCli, ComputeRefusesEveryEscapeAndWritesNothing) {
  const std::size_t before = files_in(h_.assets);
  for (const auto& [file, uri] : h_.evil) {
    const fs::path out = h_.assets / "out.glb";
    const auto r = run("compute " + file.string() + " -o " + out.string());
    expect_clean_error(r, file.string() + ": external reference '" + uri + "'");
    EXPECT_NE(r.err.find("--allow-external-paths"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("bytes"), std::string::npos) << r.err;  // nothing about the target
    EXPECT_FALSE(fs::exists(out)) << file;
    EXPECT_EQ(files_in(h_.assets), before) << "a temporary file was left behind";
  }
}

TEST_F(UntrustedCli, SkeletonAndInfoRefuseToo) {
  for (const auto& [file, uri] : h_.evil) {
    expect_clean_error(run("info " + file.string()), "'" + uri + "'");
    const fs::path out = dir_ / "skeleton.json";
    expect_clean_error(run("skeleton " + file.string() + " -o " + out.string()), "'" + uri + "'");
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST_F(UntrustedCli, AllowExternalPathsLiftsIt) {
  for (const auto& [file, uri] : h_.evil) {
    const auto r = run("info --json --allow-external-paths " + file.string());
    EXPECT_EQ(r.exit_code, 0) << uri << ": " << r.err;
    EXPECT_NE(r.out.find("\"faces\": 4"), std::string::npos) << r.out;
  }
  EXPECT_EQ(run("info " + h_.ok.string()).exit_code, 0);  // inside its directory: always fine
}

TEST_F(UntrustedCli, LimitsRefuseBigAssetsBeforeComputing) {
  const std::string cow = sdfkit::test::data_mesh("cow.off");  // 5804 triangles
  const fs::path out = dir_ / "cow.txt";
  expect_clean_error(run("compute " + cow + " -o " + out.string() + " --max-triangles 5000"),
                     "cow.off: 5804 faces, more than the limit of 5000 triangles");
  EXPECT_FALSE(fs::exists(out));
  expect_clean_error(run("info " + cow + " --max-file-size 100K"), "more than the limit of 102400");
  const auto ok = run("info " + cow + " --max-file-size 1M --max-triangles 5804");
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  // 0 = no limit; malformed values are usage errors.
  EXPECT_EQ(run("info " + cow + " --max-file-size 0 --max-triangles 0").exit_code, 0);
  for (const char* bad : {"--max-triangles -3", "--max-triangles many", "--max-file-size lots"}) {
    const auto r = run("info " + cow + " " + bad);
    EXPECT_FALSE(r.signaled);
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.err;
  }
}

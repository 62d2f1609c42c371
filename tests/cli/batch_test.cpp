// Batch planning without a device: input expansion, shards, output names.
#include "scratch.hpp"

#include "sdfkit/batch.hpp"
#include "sdfkit/pipeline.hpp"
#include "sdfkit/core/error.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>

namespace fs = std::filesystem;
using namespace sdfkit;

namespace {
class BatchPlan : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = scratch_.dir();
    fs::create_directories(dir_ / "a" / "deep");
    fs::create_directories(dir_ / "b");
    for (const char* f : {"a/x.off", "a/deep/y.glb", "a/notes.txt", "b/x.off", "b/z.PLY"})
      std::ofstream(dir_ / f) << "x";
  }
  sdfkit::test::ScratchDir scratch_;
  fs::path dir_;
};
}  // namespace

TEST_F(BatchPlan, DirectoriesAreSearchedForMeshFilesOnly) {
  const auto files = expand_inputs({dir_.string()});
  ASSERT_EQ(files.size(), 4u);  // notes.txt is not a mesh
  EXPECT_TRUE(std::is_sorted(files.begin(), files.end()));
}

TEST_F(BatchPlan, ManifestsResolveRelativePathsAndDeduplicate) {
  std::ofstream(dir_ / "jobs.list") << "# two assets\na/x.off\n\n  b/z.PLY  \na/x.off\n";
  const auto files = expand_inputs({(dir_ / "jobs.list").string(), (dir_ / "a" / "x.off").string()});
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(fs::path(files[0]).filename(), "x.off");
  EXPECT_EQ(fs::path(files[1]).filename(), "z.PLY");
}

TEST_F(BatchPlan, TxtFilesAreManifests) {
  std::ofstream(dir_ / "assets.txt") << "b/x.off\n";
  const auto files = expand_inputs({(dir_ / "assets.txt").string()});
  ASSERT_EQ(files.size(), 1u);
  EXPECT_EQ(fs::path(files[0]).parent_path().filename(), "b");
}

TEST_F(BatchPlan, AtLineInAManifestIsAManifestRelativeToIt) {
  // "@FILE" inside a manifest names another manifest relative to the listing one, as "@FILE"
  // names one on the command line; "./@name" is a file whose name starts with '@'.
  fs::create_directories(dir_ / "lists" / "sub");
  std::ofstream(dir_ / "lists" / "sub" / "more.manifest") << "../../b/x.off\n";
  std::ofstream(dir_ / "lists" / "@odd.off") << "x";
  std::ofstream(dir_ / "lists" / "main.list") << "@sub/more.manifest\n./@odd.off\n../a/x.off\n";
  const auto files = expand_inputs({"@" + (dir_ / "lists" / "main.list").string()});
  ASSERT_EQ(files.size(), 3u);
  std::set<std::string> got;
  for (const auto& f : files) got.insert(fs::relative(f, dir_).string());
  EXPECT_EQ(got, (std::set<std::string>{"a/x.off", "b/x.off", "lists/@odd.off"}));
  // Without the rule the line would be the file "lists/@sub/more.manifest", which is missing.
  std::ofstream(dir_ / "lists" / "lone.list") << "@\n";
  EXPECT_THROW(expand_inputs({(dir_ / "lists" / "lone.list").string()}), InputError);
}

TEST_F(BatchPlan, MissingInputIsAnError) {
  EXPECT_THROW(expand_inputs({(dir_ / "nope").string()}), InputError);
  std::ofstream(dir_ / "bad.list") << "missing.off\n";
  EXPECT_THROW(expand_inputs({(dir_ / "bad.list").string()}), InputError);
}

TEST(BatchShard, ShardsAreDisjointAndCoverEverything) {
  std::vector<std::string> inputs;
  for (int i = 0; i < 23; ++i) inputs.push_back("f" + std::to_string(100 + i));
  std::multiset<std::string> seen;
  for (int i = 0; i < 4; ++i)
    for (const auto& s : select_shard(inputs, i, 4)) seen.insert(s);
  EXPECT_EQ(seen.size(), inputs.size());
  EXPECT_EQ(std::set<std::string>(seen.begin(), seen.end()).size(), inputs.size());
}

TEST(BatchShard, ParsesIOverN) {
  EXPECT_EQ(parse_shard("3/8"), std::make_pair(3, 8));
  for (const char* bad : {"8/8", "-1/4", "1", "a/b", "1/0", "1/2x"}) EXPECT_THROW(parse_shard(bad), InputError) << bad;
}

TEST(BatchPlanOutputs, CollidingStemsGetAStableSuffix) {
  const auto out = plan_outputs({"/p/a/x.off", "/p/b/x.off", "/p/c/y.obj"}, "/out", "glb");
  EXPECT_NE(out[0], out[1]);
  EXPECT_EQ(out[2], "/out/y.glb");
  EXPECT_EQ(plan_outputs({"/p/a/x.off", "/p/b/x.off"}, "/out", "glb"), std::vector<std::string>(out.begin(), out.begin() + 2));
}

// The JSON report's total adds the host stages only: a nested device-pass time ("gpu_*", part
// of a host stage) is listed but not counted twice.
TEST(ComputeReportJson, TotalSkipsNestedStages) {
  sdfkit::ComputeReport r;
  r.stages = {{"load", 2.0}, {"lists_and_resolve", 10.0}, {"gpu_fragment_lists", 9.0, true}};
  const std::string text = sdfkit::report_to_json(r);
  EXPECT_NE(text.find("\"gpu_fragment_lists\": 9.0"), std::string::npos) << text;
  EXPECT_NE(text.find("\"total_ms\": 12.0"), std::string::npos) << text;
}

// `sdfkit batch` end to end on real files with the OpenCL backend (PoCL in CI): one bad asset
// does not stop the others, results are atomic with per-asset records, a rerun resumes, and
// shards split the work.
#include "analytic.hpp"
#include "scratch.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <chrono>
#include <cstdlib>
#include <iterator>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

class BatchRun : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = scratch_.dir();
    fs::create_directories(dir_ / "in");
    for (const char* m : {"cow.off", "elephant.off", "cube-ouvert.off"})
      fs::copy_file(sdfkit::test::data_mesh(m), dir_ / "in" / m);
    std::ofstream(dir_ / "in" / "broken.off") << "OFF\n3 1 0\n0 0 0\n1 0 0\n";
  }

  int batch(const std::string& args, int rays = 6) {
    const std::string cmd = std::string(SDFKIT_CLI) + " batch " + (dir_ / "in").string() + " --out " +
                            (dir_ / "out").string() + " --backend opencl --rays " + std::to_string(rays) + " --format txt " + args +
                            " >" + (dir_ / "log.txt").string() + " 2>&1";
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  // Status per input file name from a final report.
  std::map<std::string, std::string> statuses(const std::string& report = "batch-report.json") {
    std::ifstream f(dir_ / "out" / report);
    const auto j = nlohmann::json::parse(f);
    std::map<std::string, std::string> out;
    for (const auto& a : j.at("assets"))
      out[fs::path(a.at("input").get<std::string>()).filename().string()] = a.at("status").get<std::string>();
    return out;
  }
  sdfkit::test::ScratchDir scratch_;  // unique per run: two trees may run the suite at once
  fs::path dir_;
};

}  // namespace

TEST_F(BatchRun, BadAssetIsReportedAndTheOthersComplete) {
  EXPECT_EQ(batch("-j 2"), 1);  // one asset failed
  const auto s = statuses();
  EXPECT_EQ(s.at("cow.off"), "done");
  EXPECT_EQ(s.at("elephant.off"), "done");
  EXPECT_EQ(s.at("cube-ouvert.off"), "done");
  EXPECT_EQ(s.at("broken.off"), "failed");
  for (const char* stem : {"cow", "elephant", "cube-ouvert"}) {
    EXPECT_TRUE(fs::exists(dir_ / "out" / (std::string(stem) + ".txt")));
    std::ifstream rec(dir_ / "out" / (std::string(stem) + ".json"));
    const auto j = nlohmann::json::parse(rec);
    EXPECT_TRUE(j.at("ok").get<bool>());
    EXPECT_EQ(j.at("backend"), "opencl");
    EXPECT_GT(j.at("counts").at("points").get<int>(), 0);
  }
  std::ifstream rec(dir_ / "out" / "broken.json");
  const auto j = nlohmann::json::parse(rec);
  EXPECT_FALSE(j.at("ok").get<bool>());
  EXPECT_NE(j.at("error").get<std::string>().find("broken.off"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "out" / "broken.txt"));
  for (const auto& e : fs::directory_iterator(dir_ / "out"))  // no temporary files left
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

TEST_F(BatchRun, RerunSkipsCompleteResultsAndResumesTheRest) {
  batch("");
  // A killed batch: one result lost its record, one its output.
  fs::remove(dir_ / "out" / "cow.json");
  fs::remove(dir_ / "out" / "elephant.txt");
  const auto cube_time = fs::last_write_time(dir_ / "out" / "cube-ouvert.txt");
  EXPECT_EQ(batch(""), 1);
  const auto s = statuses();
  EXPECT_EQ(s.at("cow.off"), "done");
  EXPECT_EQ(s.at("elephant.off"), "done");
  EXPECT_EQ(s.at("cube-ouvert.off"), "skipped");
  EXPECT_EQ(fs::last_write_time(dir_ / "out" / "cube-ouvert.txt"), cube_time);
  // Other options are another result: recomputed, as is everything with --force.
  batch("", 7);
  EXPECT_EQ(statuses().at("cube-ouvert.off"), "done");
  batch("--force", 7);
  EXPECT_EQ(statuses().at("cow.off"), "done");
}

// A run with other options killed after its output's rename and before its record's leaves a new
// output beside the old record: a rerun with the old options must not take it for its result.
TEST_F(BatchRun, AnOutputReplacedAfterItsRecordIsRecomputed) {
  batch("");
  ASSERT_EQ(statuses().at("cow.off"), "done");
  const fs::path out = dir_ / "out" / "cow.txt";
  const auto stamp = fs::last_write_time(out);
  std::ofstream(out, std::ios::app) << "# written by another run\n";
  fs::last_write_time(out, stamp + std::chrono::seconds(1));
  batch("");
  const auto s = statuses();
  EXPECT_EQ(s.at("cow.off"), "done");
  EXPECT_EQ(s.at("elephant.off"), "skipped");
  std::ifstream f(out);
  const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.find("another run"), std::string::npos);
}

TEST_F(BatchRun, TemporariesOfAKilledRunAreRemovedOnResume) {
  fs::remove(dir_ / "in" / "broken.off");
  ASSERT_EQ(batch("-j 2"), 0);
  // What a SIGKILL between write and rename leaves (io::write_file_atomically's names): this
  // batch's result, record and report temporaries, and one of an asset this batch does not
  // own (another shard's, writing into the same directory right now).
  const std::vector<std::string> ours = {"cow.txt.tmp-a1b2c3d4", "elephant.json.tmp-zz99zz99",
                                         "batch-report.json.tmp-00000000"};
  for (const auto& t : ours) std::ofstream(dir_ / "out" / t) << "partial";
  std::ofstream(dir_ / "out" / "horse.txt.tmp-a1b2c3d4") << "another shard's";
  std::ofstream(dir_ / "out" / "cow.txt.tmp-short") << "not a temporary name";
  ASSERT_EQ(batch("-j 2"), 0);
  for (const auto& t : ours) EXPECT_FALSE(fs::exists(dir_ / "out" / t)) << t;
  EXPECT_TRUE(fs::exists(dir_ / "out" / "horse.txt.tmp-a1b2c3d4"));
  EXPECT_TRUE(fs::exists(dir_ / "out" / "cow.txt.tmp-short"));
  std::ifstream f(dir_ / "out" / "batch-report.json");
  const auto j = nlohmann::json::parse(f);
  EXPECT_EQ(j.at("stale_temporaries_removed").get<int>(), 3);
  EXPECT_EQ(j.at("skipped").get<int>(), 3);
}

TEST_F(BatchRun, ReportSaysWhereTheTimeWentWithOneSessionPerWorker) {
  fs::remove(dir_ / "in" / "broken.off");
  for (int i = 0; i < 5; ++i) fs::copy_file(dir_ / "in" / "cow.off", dir_ / "in" / ("cow" + std::to_string(i) + ".off"));
  ASSERT_EQ(batch("-j 2"), 0);
  std::ifstream f(dir_ / "out" / "batch-report.json");
  const auto t = nlohmann::json::parse(f).at("timing");
  // 8 assets on 2 workers: 2 sessions (device, kernels) for the whole batch, not one per asset.
  EXPECT_EQ(t.at("sessions").get<int>(), 2);
  const auto& per = t.at("per_asset_mean_ms");
  for (const char* stage : {"load", "read", "weld", "orient", "device", "bvh_build", "upload", "trace_gather", "write", "record", "other"})
    ASSERT_TRUE(per.contains(stage)) << stage;
  for (const auto& [stage, ms] : per.items()) EXPECT_GE(ms.get<double>(), 0.0) << stage;
  // Stages are parts of the asset's time: their mean sum (read, weld, orient are inside load) is
  // the mean asset time, which two workers overlap, so it is at most twice the wall time per asset.
  double sum = 0;
  for (const auto& [stage, ms] : per.items())
    if (stage != "read" && stage != "weld" && stage != "orient") sum += ms.get<double>();
  EXPECT_LE(sum * 8, 2 * t.at("wall_ms").get<double>() + 1.0);
  // With one job, one session.
  ASSERT_EQ(batch("-j 1 --force"), 0);
  std::ifstream g(dir_ / "out" / "batch-report.json");
  EXPECT_EQ(nlohmann::json::parse(g).at("timing").at("sessions").get<int>(), 1);
}

TEST_F(BatchRun, ShardsAreDisjointAndCoverTheInputs) {
  fs::remove(dir_ / "in" / "broken.off");
  EXPECT_EQ(batch("--shard 0/2"), 0);
  EXPECT_EQ(batch("--shard 1/2"), 0);
  const auto a = statuses("batch-report-shard0-of-2.json");
  const auto b = statuses("batch-report-shard1-of-2.json");
  EXPECT_EQ(a.size() + b.size(), 3u);
  for (const auto& [name, status] : a) EXPECT_EQ(b.count(name), 0u) << name;
  for (const char* stem : {"cow", "elephant", "cube-ouvert"})
    EXPECT_TRUE(fs::exists(dir_ / "out" / (std::string(stem) + ".txt")));
}

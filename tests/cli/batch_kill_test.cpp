// Issue 15: `sdfkit batch` killed for real (SIGKILL, mid-run) and run again loses at most the
// assets that were in flight: every result complete before the kill is skipped, the rest are
// computed, and every output ends up whole.
#include "analytic.hpp"
#include "scratch.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace fs = std::filesystem;

namespace {

constexpr int kAssets = 160;

// A record says ok and its output exists: what a rerun may skip.
bool complete(const fs::path& out, const std::string& stem) {
  std::ifstream rec(out / (stem + ".json"));
  if (!rec || !fs::exists(out / (stem + ".txt"))) return false;
  const auto j = nlohmann::json::parse(rec, nullptr, false);
  return j.is_object() && j.value("ok", false);
}

std::size_t lines(const fs::path& p) {
  std::ifstream f(p);
  std::size_t n = 0;
  for (std::string s; std::getline(f, s);) ++n;
  return n;
}

}  // namespace

TEST(BatchKill, RerunAfterSigkillRedoesOnlyWhatWasNotComplete) {
  const sdfkit::test::ScratchDir scratch;  // unique per run: two trees may run the suite at once
  const fs::path dir = scratch.dir();
  fs::remove_all(dir);
  fs::create_directories(dir / "in");
  for (int i = 0; i < kAssets; ++i)
    fs::copy_file(sdfkit::test::data_mesh("cow.off"), dir / "in" / ("cow" + std::to_string(1000 + i) + ".off"));
  const fs::path out = dir / "out";
  std::vector<std::string> args = {SDFKIT_CLI, "batch", (dir / "in").string(), "--out", out.string(),
                                   "--backend", "opencl", "--rays", "6", "--format", "txt", "-j", "2"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, (dir / "log1.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);

  // Kill it once a few assets are done (or after 60 s).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  auto records = [&] {
    std::size_t n = 0;
    std::error_code ec;
    if (fs::exists(out, ec))
      for (const auto& e : fs::directory_iterator(out, ec)) n += e.path().extension() == ".json";
    return n;
  };
  while (records() < 6 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(kill(pid, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the batch ended before it was killed";

  std::set<std::string> done_before;
  for (int i = 0; i < kAssets; ++i) {
    const std::string stem = "cow" + std::to_string(1000 + i);
    if (complete(out, stem)) done_before.insert(stem);
  }
  ASSERT_GE(done_before.size(), 1u);
  ASSERT_LT(done_before.size(), static_cast<std::size_t>(kAssets)) << "nothing was left to resume";

  // The rerun: what was complete is skipped, everything else computed.
  const std::string rerun = "'" + args[0] + "' batch '" + (dir / "in").string() + "' --out '" + out.string() +
                            "' --backend opencl --rays 6 --format txt -j 2 > '" + (dir / "log2.txt").string() + "' 2>&1";
  ASSERT_EQ(std::system(rerun.c_str()), 0);
  std::ifstream report(out / "batch-report.json");
  const auto j = nlohmann::json::parse(report);
  std::size_t skipped = 0, done = 0;
  for (const auto& a : j.at("assets")) {
    const std::string stem = fs::path(a.at("input").get<std::string>()).stem().string();
    const std::string s = a.at("status").get<std::string>();
    EXPECT_EQ(s, done_before.count(stem) ? "skipped" : "done") << stem;
    skipped += s == "skipped";
    done += s == "done";
    EXPECT_EQ(lines(out / (stem + ".txt")), 2904u) << stem;  // cow: one value per vertex, whole
  }
  EXPECT_EQ(skipped, done_before.size());
  EXPECT_EQ(skipped + done, static_cast<std::size_t>(kAssets));
  fs::remove_all(dir);
}

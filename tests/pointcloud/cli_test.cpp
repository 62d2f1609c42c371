// `sdfkit pointcloud-skeleton` and `sdfkit compress-animation` end to end (PoCL): JSON polylines
// for a file and a sequence, a skinned glb that the Khronos validator passes with 0 errors and a
// report that meets the targets, and bad input as one error line with no output file.
#include "scratch.hpp"

#include "sdfkit/pointcloud/pointcloud.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <glm/geometric.hpp>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace fs = std::filesystem;
namespace pc = sdfkit::pointcloud;

namespace {
int run(const std::string& args, const fs::path& log) {
  const int status = std::system((std::string(SDFKIT_CLI) + " " + args + " >" + log.string() + " 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}
void write_xyz(const fs::path& p, const std::vector<glm::vec3>& pts) {
  std::ofstream out(p);
  for (const auto& q : pts) out << q.x << ' ' << q.y << ' ' << q.z << '\n';
}
const std::string kWorm = std::string(SDFKIT_SOURCE_DIR) + "/tests/data/worm";
}  // namespace

TEST(PointcloudCli, SingleCloudGivesNPlusOneOrderedNodes) {
  sdfkit::test::ScratchDir d;
  pc::WormShape shape;
  const pc::SyntheticWorm w = pc::synthetic_worm(shape);
  write_xyz(d.dir() / "worm.xyz", w.points);
  const fs::path out = d.dir() / "s.json";
  ASSERT_EQ(run("pointcloud-skeleton " + (d.dir() / "worm.xyz").string() + " -o " + out.string() + " --segments 8 --nodes 20",
                d.dir() / "log"),
            0)
      << slurp(d.dir() / "log");
  const auto j = nlohmann::json::parse(slurp(out));
  ASSERT_EQ(j.at("nodes").size(), 9u);
  EXPECT_EQ(j.at("subdivided").at("nodes").size(), 20u);
  EXPECT_TRUE(j.at("exact_segments").get<bool>());
  pc::Polyline line;
  for (const auto& n : j["nodes"]) {
    line.nodes.push_back({{n["position"][0], n["position"][1], n["position"][2]}, n["radius"]});
    EXPECT_GT(n["radius"].get<float>(), 0.0f);
  }
  EXPECT_LT(pc::mean_distance(line, w.midline, 0.25f), 0.01f * w.length);
}

TEST(PointcloudCli, SequenceDirectoryKeepsTheSameEndFirst) {
  sdfkit::test::ScratchDir d;
  fs::create_directories(d.dir() / "frames");
  std::vector<pc::SyntheticWorm> worms;
  for (int f = 0; f < 3; ++f) {
    pc::WormShape shape;
    shape.phase = 0.3f * static_cast<float>(f);
    shape.seed = static_cast<std::uint32_t>(f + 7);
    worms.push_back(pc::synthetic_worm(shape));
    write_xyz(d.dir() / "frames" / ("f" + std::to_string(f) + ".xyz"), worms.back().points);
  }
  const fs::path out = d.dir() / "seq.json";
  ASSERT_EQ(run("pointcloud-skeleton " + (d.dir() / "frames").string() + " -o " + out.string() + " --segments 10 -q", d.dir() / "log"), 0)
      << slurp(d.dir() / "log");
  const auto j = nlohmann::json::parse(slurp(out));
  ASSERT_EQ(j.at("frames").size(), 3u);
  int first = 0;
  for (int f = 0; f < 3; ++f) {
    const auto& n0 = j["frames"][f]["nodes"][0]["position"];
    const glm::vec3 p0(n0[0], n0[1], n0[2]);
    const auto& m = worms[static_cast<std::size_t>(f)].midline.nodes;
    const int end = glm::distance(p0, m.front().position) < glm::distance(p0, m.back().position) ? 1 : -1;
    if (f == 0) first = end;
    EXPECT_EQ(end, first);
    EXPECT_EQ(j["frames"][f]["nodes"].size(), 11u);
  }
}

TEST(PointcloudCli, BadInputIsOneErrorLineAndNoOutput) {
  sdfkit::test::ScratchDir d;
  const fs::path out = d.dir() / "o.json";
  EXPECT_EQ(run("pointcloud-skeleton " + (d.dir() / "missing.ply").string() + " -o " + out.string(), d.dir() / "log"), 1);
  EXPECT_NE(slurp(d.dir() / "log").find("sdfkit: error:"), std::string::npos);
  EXPECT_FALSE(fs::exists(out));
  std::ofstream(d.dir() / "few.xyz") << "0 0 0\n1 0 0\n0 1 0\n";
  EXPECT_EQ(run("pointcloud-skeleton " + (d.dir() / "few.xyz").string() + " -o " + out.string(), d.dir() / "log"), 1);
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(run("pointcloud-skeleton " + (d.dir() / "few.xyz").string() + " -o " + out.string() + " --segments 0", d.dir() / "log"), 2);
  EXPECT_EQ(run("pointcloud-skeleton " + (d.dir() / "few.xyz").string() + " -o " + out.string() + " --segments 4 --threshold 2",
                d.dir() / "log"),
            2);
  // Usage errors exit 2: the output's extension, the per-face SDF.
  EXPECT_EQ(run("pointcloud-skeleton " + (d.dir() / "few.xyz").string() + " -o " + (d.dir() / "o.txt").string(), d.dir() / "log"), 2);
  EXPECT_EQ(run("pointcloud-skeleton " + (d.dir() / "few.xyz").string() + " -o " + out.string() + " --per face", d.dir() / "log"), 2);
  // compress-animation: frames of different sizes; no frame time for plain files.
  fs::create_directories(d.dir() / "frames");
  std::ofstream(d.dir() / "frames" / "a.xyz") << "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
  std::ofstream(d.dir() / "frames" / "b.xyz") << "0 0 0\n1 0 0\n0 1 0\n";
  const fs::path glb = d.dir() / "o.glb";
  EXPECT_EQ(run("compress-animation " + (d.dir() / "frames").string() + " -o " + glb.string() + " --frame-time 0.1", d.dir() / "log"), 1);
  EXPECT_NE(slurp(d.dir() / "log").find("same points"), std::string::npos) << slurp(d.dir() / "log");
  EXPECT_EQ(run("compress-animation " + (d.dir() / "frames").string() + " -o " + glb.string(), d.dir() / "log"), 2);
  EXPECT_EQ(run("compress-animation " + kWorm + " -o " + (d.dir() / "o.gltf").string(), d.dir() / "log"), 2);
  EXPECT_EQ(run("compress-animation " + kWorm + " -o " + glb.string() + " --json " + (d.dir() / "r.txt").string(), d.dir() / "log"), 2);
  EXPECT_EQ(run("compress-animation " + kWorm + " -o " + glb.string() + " --bones 3", d.dir() / "log"), 2);
  EXPECT_FALSE(fs::exists(glb));
}

TEST(PointcloudCli, CompressedWormIsValidatorCleanAndMeetsTheTargets) {
  const fs::path validator = fs::path(SDFKIT_SOURCE_DIR) / "tools/gltf-validator";
  ASSERT_TRUE(fs::exists(validator / "node_modules/gltf-validator"))
      << "run scripts/install-deps.sh (installs the Khronos glTF validator from npm)";
  sdfkit::test::ScratchDir d;
  const fs::path glb = d.dir() / "worm.glb", rep = d.dir() / "worm.json";
  ASSERT_EQ(run("compress-animation " + kWorm + " -o " + glb.string() + " --bones 16 --json " + rep.string(), d.dir() / "log"), 0)
      << slurp(d.dir() / "log");
  EXPECT_EQ(std::system(("node " + (validator / "validate.js").string() + " " + glb.string() + " >" + (d.dir() / "v").string()).c_str()), 0)
      << slurp(d.dir() / "v");
  EXPECT_NE(slurp(d.dir() / "v").find("0 errors"), std::string::npos);
  const auto j = nlohmann::json::parse(slurp(rep));
  EXPECT_EQ(j.at("frames"), 100);
  EXPECT_EQ(j.at("points"), 2290);
  EXPECT_EQ(j.at("raw_bytes"), 100 * 2290 * 12);
  EXPECT_EQ(j.at("compressed_bytes"), fs::file_size(glb));
  EXPECT_GE(j.at("compression_ratio").get<double>(), 20.0);
  EXPECT_LE(j.at("rmse_percent_of_length").get<double>(), 1.0);
  EXPECT_GT(j.at("kg_error").get<double>(), 0.0);
}

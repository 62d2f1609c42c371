// `sdfkit smooth --texture-space` and `compute --smooth-texture` from the command line (issue 13):
// usage errors exit 2 before any work and write nothing; a run (skeleton, mapping, device, writer)
// writes the smoothed result, within the input's range, and the atlas PNG.

#include "run.hpp"
#include "scratch.hpp"

#include "sdfkit/core/shapes.hpp"
#include "sdfkit/io/field.hpp"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <filesystem>
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <cmath>
#include <map>

namespace sdfkit::test {
namespace {

const std::string kCli = SDFKIT_CLI;

// A capped cylinder (radius 1, length 6) as OFF and a field on it as .txt: a step at mid-length,
// a slope along the axis and waves around it.
float cylinder_field(const glm::vec3& p) {
  return 2.0f + 0.4f * std::sin(3.0f * std::atan2(p.y, p.x)) + 0.3f * p.z + (p.z > 0.0f ? 0.5f : 0.0f);
}
Mesh cylinder() { return shapes::capped_cylinder(1.0f, 6.0f, 64, 60, 8); }

void write_cylinder_and_field(const std::string& off, const std::string& txt) {
  const Mesh m = cylinder();
  std::ofstream o(off), t(txt);
  o << "OFF\n" << m.vertex_count() << " " << m.face_count() << " 0\n";
  for (const glm::vec3& p : m.positions) {
    o << p.x << " " << p.y << " " << p.z << "\n";
    t << cylinder_field(p) << "\n";
  }
  for (const auto& f : m.triangles) o << "3 " << f[0] << " " << f[1] << " " << f[2] << "\n";
}

// The same as one result file: an ASCII PLY with the field as vertex quality.
void write_cylinder_result(const std::string& ply) {
  const Mesh m = cylinder();
  std::ofstream o(ply);
  o << "ply\nformat ascii 1.0\nelement vertex " << m.vertex_count()
    << "\nproperty float x\nproperty float y\nproperty float z\nproperty float quality\nelement face "
    << m.face_count() << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const glm::vec3& p : m.positions) o << p.x << " " << p.y << " " << p.z << " " << cylinder_field(p) << "\n";
  for (const auto& f : m.triangles) o << "3 " << f[0] << " " << f[1] << " " << f[2] << "\n";
}

// `sdfkit compare --diffusion`: heat diffusion, k-ring and texture space side by side at sigma =
// 1 and 10 mean edge lengths on a capped cylinder through the skeleton texture mapping (its bone
// chart is close to isometric): heat against itself is exact, texture space stays within
// Pearson 0.95 and 5 % median of heat diffusion up to 10 edges, k-ring uses K = 2 sigma / edge.
TEST(DiffuseCli, CompareDiffusionPutsKRingAndTextureSpaceBesideHeat) {
  ScratchDir dir;
  const std::string off = dir.path("cyl.off"), txt = dir.path("cyl.txt"), json = dir.path("rows.json");
  write_cylinder_and_field(off, txt);
  const CommandResult r = run_command(kCli + " compare " + txt + " --mesh " + off +
                                          " --diffusion --sigma-edges 1,10 --atlas-size 1024 --json " + json,
                                      dir.dir());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("| method | pearson | median relative | rms | seam ratio |"), std::string::npos) << r.out;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["rows"].size(), 6u);
  std::map<std::pair<int, std::string>, nlohmann::json> rows;
  for (const auto& row : j["rows"]) rows[{static_cast<int>(std::lround(row["sigma_edges"].get<double>())), row["method"]}] = row;
  for (int e : {1, 10}) {
    const auto& heat = rows.at({e, "heat"});
    EXPECT_EQ(heat["pearson"].get<double>(), 1.0);
    EXPECT_EQ(heat["rms"].get<double>(), 0.0);
    EXPECT_NEAR(heat["sigma"].get<double>(), e * j["mean_edge"].get<double>(), 1e-9);
    const auto& tex = rows.at({e, "texture"});
    EXPECT_GE(tex["pearson"].get<double>(), 0.95) << e;
    EXPECT_LE(tex["median_relative"].get<double>(), 0.05) << e;
    EXPECT_GT(tex["rms"].get<double>(), 0.0) << e;  // not the heat values themselves
    // Every row's seam ratio over the texture space's charts; texture space's no worse than 1.5x
    // what the seamless heat field gives over the same borders.
    ASSERT_TRUE(heat.contains("seam_ratio") && tex.contains("seam_ratio"));
    std::printf("cylinder sigma %d edges: seam ratio heat %.3f, texture %.3f\n", e, heat["seam_ratio"].get<double>(),
                tex["seam_ratio"].get<double>());
    EXPECT_GT(heat["seam_ratio"].get<double>(), 0.0) << e;
    EXPECT_LE(tex["seam_ratio"].get<double>(), 1.5 * std::max(1.0, heat["seam_ratio"].get<double>())) << e;
    const auto& kring = rows.at({e, "k-ring"});
    EXPECT_EQ(kring["rings"].get<int>(), 2 * e);
    EXPECT_GE(kring["pearson"].get<double>(), 0.95) << e;
  }
  // Texture space's distance from heat diffusion grows with sigma (the bone chart ends at the
  // caps, which the blur does not cross); a run that ignored sigma would give equal rows.
  EXPECT_LT(rows.at({1, "texture"})["rms"].get<double>(), rows.at({10, "texture"})["rms"].get<double>());
}

TEST(DiffuseCli, CompareDiffusionUsageErrorsExitTwo) {
  ScratchDir dir;
  const std::string off = dir.path("cyl.off"), txt = dir.path("cyl.txt"), json = dir.path("rows.json");
  write_cylinder_and_field(off, txt);
  const std::string base = kCli + " compare " + txt + " --mesh " + off + " ";
  for (const std::string& args : {"--diffusion --json " + json, "--diffusion --sigma 0.1 --sigma-edges 1 --json " + json,
                                 "--sigma-edges 1 --json " + json, "--diffusion --sigma-edges 1 " + txt + " --json " + json,
                                 "--diffusion --sigma-edges 0 --json " + json, "--json " + json}) {
    const CommandResult r = run_command(base + args, dir.dir());
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(json)) << args;
  }
  // A mesh without values is an input error (exit 1), not a usage error.
  const CommandResult r = run_command(kCli + " compare " + off + " --diffusion --sigma-edges 1", dir.dir());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.exit_code, 2) << r.err;
}

TEST(DiffuseCli, UsageErrorsExitTwo) {
  ScratchDir dir;
  const std::string in = dir.path("none.ply"), out = dir.path("out.ply");
  for (const std::string args : {"--texture-space", "--texture-space --radius 2 --sigma 0.1",
                                  "--texture-space --radius 2 --rings 3", "--radius 2", "--atlas-png a.png",
                                  "--texture-space --radius 2 --atlas-png atlas.jpg",
                                  "--texture-space --radius 2 --atlas-size 8", "--steps 2",
                                  "--texture-space --radius 2 --steps 257", "--texture-space --radius 2 --steps -1",
                                  "--no-conserve", "--no-stretch", "--texture-space --radius 2 --no-stretch"}) {
    const CommandResult r = run_command(kCli + " smooth " + in + " -o " + out + " " + args, dir.dir());
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
  for (const std::string args : {"--smooth-texture 4 --smooth 2", "--smooth-texture 4 --per face", "--smooth-texture -1"}) {
    const CommandResult r = run_command(kCli + " compute builtin:sphere -o " + out + " " + args, dir.dir());
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
}

// An output that cannot hold the values is the error, before any work: with a Vulkan device that
// does not exist, the device would be the error had the diffusion started first. Nothing written.
TEST(DiffuseCli, AnOutputThatCannotHoldTheValuesIsRefusedBeforeTheWork) {
  ScratchDir dir;
  const std::string ply = dir.path("cyl.ply");
  write_cylinder_result(ply);
  CommandResult r = run_command(kCli + " smooth " + ply + " -o " + dir.path("ok.txt") + " -k 1 -q", dir.dir());
  ASSERT_EQ(r.exit_code, 0) << r.err;  // the result file itself is good
  const std::pair<const char*, const char*> cases[] = {
      {"out.xyz", "unknown extension '.xyz'; write .gltf, .glb, .ply or .txt"},
      {"out.off", "cannot store values in .off files"},
      {"out", "no file extension"}};
  for (const auto& [name, what] : cases)
    for (const std::string mode : {"--texture-space --radius 2 --device no-such-device", "-k 2"}) {
      const std::string out = dir.path(name);
      r = run_command(kCli + " smooth " + ply + " -o " + out + " " + mode, dir.dir());
      EXPECT_EQ(r.exit_code, 2) << name << " " << mode << ": " << r.err;  // a usage error
      EXPECT_EQ(r.err.rfind("sdfkit: usage error: " + out + ": ", 0), 0u) << r.err;
      EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
      EXPECT_FALSE(std::filesystem::exists(out)) << out;
    }
}

TEST(DiffuseCli, SmoothTextureSpaceWritesTheResultAndTheAtlas) {
  ScratchDir dir;
  // The SDF of a capsule, itself texture-smoothed by compute; smoothed again it stays in its range.
  const std::string sdf = dir.path("capsule.ply");
  CommandResult r = run_command(kCli + " compute builtin:capsule -o " + sdf + " --smooth-texture 4 -q", dir.dir());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string out = dir.path("smoothed.ply"), png = dir.path("atlas.png");
  r = run_command(kCli + " smooth " + sdf + " -o " + out + " --texture-space --sigma 0.05 --atlas-size 512 --atlas-png " +
                      png,
                  dir.dir());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("diffused in texture space"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" step"), std::string::npos) << "the run says how many blur steps it took: " << r.out;
  // --steps is honoured: one blur and three steps of the same sigma differ.
  const std::string one = dir.path("one.ply"), three = dir.path("three.ply");
  for (const auto& [file, n] : {std::pair{one, 1}, std::pair{three, 3}}) {
    const CommandResult s = run_command(kCli + " smooth " + sdf + " -o " + file + " --texture-space --sigma 0.05 --atlas-size 512 --steps " +
                                            std::to_string(n),
                                        dir.dir());
    ASSERT_EQ(s.exit_code, 0) << s.err;
    EXPECT_NE(s.out.find("in " + std::to_string(n) + " step"), std::string::npos) << s.out;
  }
  const io::FieldFile v1 = io::read_field(one, io::ValuesRequired::Yes), v3 = io::read_field(three, io::ValuesRequired::Yes);
  ASSERT_EQ(v1.values.size(), v3.values.size());
  float most = 0.0f;
  for (std::size_t i = 0; i < v1.values.size(); ++i) most = std::max(most, std::abs(v1.values[i] - v3.values[i]));
  EXPECT_GT(most, 0.0f);
  // So are --no-stretch and --no-conserve: each changes the result of the same run.
  const io::FieldFile plain = io::read_field(out, io::ValuesRequired::Yes);
  for (const std::string flag : {"--no-stretch", "--no-conserve"}) {
    const std::string file = dir.path("flag.ply");
    const CommandResult s = run_command(kCli + " smooth " + sdf + " -o " + file + " --texture-space --sigma 0.05 --atlas-size 512 " + flag, dir.dir());
    ASSERT_EQ(s.exit_code, 0) << flag << ": " << s.err;
    const io::FieldFile other = io::read_field(file, io::ValuesRequired::Yes);
    ASSERT_EQ(other.values.size(), plain.values.size());
    float diff = 0.0f;
    for (std::size_t i = 0; i < other.values.size(); ++i) diff = std::max(diff, std::abs(other.values[i] - plain.values[i]));
    EXPECT_GT(diff, 1e-6f) << flag;
  }
  const io::FieldFile before = io::read_field(sdf, io::ValuesRequired::Yes), after = io::read_field(out, io::ValuesRequired::Yes);
  ASSERT_EQ(before.values.size(), after.values.size());
  float lo = 1e30f, hi = -1e30f, alo = 1e30f, ahi = -1e30f;
  for (std::size_t i = 0; i < before.values.size(); ++i) {
    lo = std::min(lo, before.values[i]);
    hi = std::max(hi, before.values[i]);
    alo = std::min(alo, after.values[i]);
    ahi = std::max(ahi, after.values[i]);
  }
  EXPECT_GE(alo, lo - 1e-4f);  // a Gaussian never leaves the input's range
  EXPECT_LE(ahi, hi + 1e-4f);
  std::ifstream f(png, std::ios::binary);
  char sig[8] = {};
  f.read(sig, 8);
  EXPECT_EQ(std::string(sig + 1, 3), "PNG");
}

// A glTF output carries the mapping as TEXCOORD_1 (and TEXCOORD_0, which glTF requires before it);
// a PLY output cannot and has none.
TEST(DiffuseCli, GltfOutputCarriesTheMappingAsTexcoord1) {
  ScratchDir dir;
  const std::string sdf = dir.path("capsule.ply");
  CommandResult r = run_command(kCli + " compute builtin:capsule -o " + sdf + " -q", dir.dir());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string glb = dir.path("smoothed.glb");
  r = run_command(kCli + " smooth " + sdf + " -o " + glb + " --texture-space --radius 4 --atlas-size 512", dir.dir());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("TEXCOORD_1"), std::string::npos) << r.out;
  const auto contains = [](const std::string& path, const std::string& what) {
    std::ifstream f(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    return bytes.find(what) != std::string::npos;
  };
  EXPECT_TRUE(contains(glb, "\"TEXCOORD_1\""));
  EXPECT_TRUE(contains(glb, "\"TEXCOORD_0\""));
  const std::string ply = dir.path("smoothed.ply");
  r = run_command(kCli + " smooth " + sdf + " -o " + ply + " --texture-space --radius 4 --atlas-size 512", dir.dir());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.find("TEXCOORD_1"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace sdfkit::test

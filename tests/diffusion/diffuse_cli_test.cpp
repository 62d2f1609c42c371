// `sdfkit smooth --texture-space` and `compute --smooth-texture` from the command line (issue 13):
// usage errors exit 2 before any work and write nothing; a run (skeleton, mapping, device, writer)
// writes the smoothed result, within the input's range, and the atlas PNG.

#include "run.hpp"
#include "scratch.hpp"

#include "sdfkit/io/field.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

namespace sdfkit::test {
namespace {

const std::string kCli = SDFKIT_CLI;

TEST(DiffuseCli, UsageErrorsExitTwo) {
  ScratchDir dir;
  const std::string in = dir.path("none.ply"), out = dir.path("out.ply");
  for (const std::string args : {"--texture-space", "--texture-space --radius 2 --sigma 0.1",
                                  "--texture-space --radius 2 --rings 3", "--radius 2", "--atlas-png a.png",
                                  "--texture-space --radius 2 --atlas-png atlas.jpg",
                                  "--texture-space --radius 2 --atlas-size 8"}) {
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

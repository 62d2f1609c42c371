// The glTF that sdfkit writes passes the Khronos glTF validator with zero errors: a fresh asset
// from an OFF mesh, the write-back of a glTF asset, and a .gltf with its buffer beside it.
#include "analytic.hpp"
#include "scratch.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

namespace fs = std::filesystem;

namespace {
int sh(const std::string& cmd) { return std::system((cmd + " >/dev/null 2>&1").c_str()); }
std::string validator() { return std::string(SDFKIT_SOURCE_DIR) + "/tools/gltf-validator/validate.js"; }
}  // namespace

class GltfValidator : public ::testing::Test {
protected:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(fs::path(SDFKIT_SOURCE_DIR) / "tools/gltf-validator/node_modules/gltf-validator"))
        << "run scripts/install-deps.sh (installs the Khronos glTF validator from npm)";
    scratch_ = std::make_unique<sdfkit::test::ScratchDir>();
    dir_ = scratch_->dir();
  }
  int compute(const std::string& in, const std::string& out) {
    return sh(std::string(SDFKIT_CLI) + " compute " + in + " -o " + (dir_ / out).string() +
              " --backend opencl --rays 8 --quiet");
  }
  int validate(const std::string& files) {
    return std::system(("node " + validator() + " " + files).c_str());
  }
  std::unique_ptr<sdfkit::test::ScratchDir> scratch_;
  fs::path dir_;
};

TEST_F(GltfValidator, FreshAssetFromOff) {
  ASSERT_EQ(compute(sdfkit::test::data_mesh("elephant.off"), "elephant.glb"), 0);
  EXPECT_EQ(validate((dir_ / "elephant.glb").string()), 0);
}

TEST_F(GltfValidator, WriteBackOfAGltfAssetAndGltfWithExternalBuffer) {
  ASSERT_EQ(compute("builtin:torus", "torus.glb"), 0);
  ASSERT_EQ(compute((dir_ / "torus.glb").string(), "again.glb"), 0);
  ASSERT_EQ(compute((dir_ / "torus.glb").string(), "again.gltf"), 0);
  EXPECT_EQ(validate((dir_ / "torus.glb").string() + " " + (dir_ / "again.glb").string() + " " +
                     (dir_ / "again.gltf").string()),
            0);
}

// `sdfkit batch` over a directory holding hostile and oversized assets (OpenCL on PoCL in CI):
// each is reported failed with its reason and the batch goes on; nothing is written for them.
// With --allow-external-paths the same assets compute, the outside image embedded as today.
#include "analytic.hpp"
#include "run.hpp"
#include "untrusted_fixture.hpp"
#include "scratch.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>

namespace fs = std::filesystem;

namespace {

class UntrustedBatch : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = scratch_.dir();
    h_ = sdfkit::test::make_hostile_assets(dir_, "in");
    fs::copy_file(sdfkit::test::data_mesh("cow.off"), h_.assets / "cow.off");  // 5804 triangles
  }

  sdfkit::test::CommandResult run(const std::string& args) {
    return sdfkit::test::run_command(std::string(SDFKIT_CLI) + " " + args, dir_);
  }
  sdfkit::test::ScratchDir scratch_;  // unique per run: two trees may run the suite at once
  fs::path dir_;
  sdfkit::test::HostileAssets h_;
};

}  // namespace

TEST_F(UntrustedBatch, RefusedAssetsFailWithTheirReasonAndTheBatchGoesOn) {
  const fs::path out = dir_ / "out";
  const auto r = run("batch " + h_.assets.string() + " --out " + out.string() +
                     " --backend opencl --rays 6 --format glb --max-triangles 1000");
  EXPECT_FALSE(r.signaled) << r.err;
  EXPECT_EQ(r.exit_code, 1) << r.err;  // some assets failed
  std::ifstream f(out / "batch-report.json");
  const auto report = nlohmann::json::parse(f);
  std::map<std::string, nlohmann::json> by_name;
  for (const auto& a : report.at("assets"))
    by_name[fs::path(a.at("input").get<std::string>()).filename().string()] = a;
  ASSERT_EQ(by_name.size(), 6u);  // ok, cow, four hostile glTF files
  EXPECT_EQ(by_name.at("ok.gltf").at("status"), "done");
  EXPECT_TRUE(fs::exists(out / "ok.glb"));
  EXPECT_EQ(by_name.at("cow.off").at("status"), "failed");
  EXPECT_NE(by_name.at("cow.off").dump().find("more than the limit of 1000 triangles"), std::string::npos)
      << by_name.at("cow.off").dump();
  for (const auto& [file, uri] : h_.evil) {
    const auto& a = by_name.at(file.filename().string());
    EXPECT_EQ(a.at("status"), "failed") << a.dump();
    EXPECT_NE(a.dump().find("external reference '" + uri + "'"), std::string::npos) << a.dump();
    EXPECT_FALSE(fs::exists(out / (file.stem().string() + ".glb"))) << file;
  }
}

TEST_F(UntrustedBatch, AllowExternalPathsComputesThemAndEmbedsTheImage) {
  const fs::path out = dir_ / "image.gltf";
  const fs::path image = h_.assets / "evil-image.gltf";
  const auto refused = run("compute " + image.string() + " -o " + out.string() + " --backend opencl --rays 6");
  EXPECT_EQ(refused.exit_code, 1) << refused.err;
  EXPECT_FALSE(fs::exists(out));
  const auto r = run("compute " + image.string() + " -o " + out.string() +
                     " --backend opencl --rays 6 --allow-external-paths");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The image's bytes are in the output as a data URI (what an output of a trusted tree gets).
  const std::string text = sdfkit::test::slurp(out);
  EXPECT_NE(text.find(sdfkit::test::base64_encode("\x89PNG SECRET-IMAGE-BYTES").substr(0, 20)), std::string::npos);
  const fs::path batch_out = dir_ / "out";
  const auto b = run("batch " + h_.assets.string() + " --out " + batch_out.string() +
                     " --backend opencl --rays 6 --format txt --allow-external-paths");
  EXPECT_EQ(b.exit_code, 0) << b.err << b.out;
  for (const auto& [file, uri] : h_.evil) EXPECT_TRUE(fs::exists(batch_out / (file.stem().string() + ".txt"))) << uri;
}

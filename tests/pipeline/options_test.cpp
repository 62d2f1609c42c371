// The road's options without a device: which backend honours which option (the contract), the
// automatic choice from a device listing, and that every option reaches the batch fingerprint.
#include "sdfkit/backends.hpp"
#include "sdfkit/batch.hpp"
#include "sdfkit/core/error.hpp"
#include "sdfkit/pipeline.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <set>
#include <string>
#include <vector>

using namespace sdfkit;

namespace {

bool both_built() {
  const auto b = built_backends();
  return std::count(b.begin(), b.end(), BackendKind::Vulkan) + std::count(b.begin(), b.end(), BackendKind::OpenCL) == 2;
}

DeviceListing device(const std::string& backend, const std::string& name, bool gpu, int index = 0) {
  DeviceListing d;
  d.backend = backend;
  d.name = name;
  d.description = "#" + std::to_string(index) + " " + name;
  d.index = index;
  d.gpu = gpu;
  return d;
}

const DeviceListing kLavapipe = device("vulkan", "llvmpipe (LLVM 15.0.6, 256 bits)", false);
const DeviceListing kPocl = device("opencl", "cpu-haswell-AMD EPYC", false);
const DeviceListing kVulkanGpu = device("vulkan", "NVIDIA H100", true, 1);
const DeviceListing kOpenClGpu = device("opencl", "NVIDIA H100", true, 1);

// One setter per backend-specific option, with the backend that honours it.
struct Setter {
  BackendOption option;
  std::function<void(BackendConfig&, SdfOptions&)> set;
};
std::vector<Setter> setters() {
  return {{BackendOption::Rays, [](BackendConfig&, SdfOptions& s) { s.rays = 4; }},
          {BackendOption::Views, [](BackendConfig& c, SdfOptions&) { c.views = 64; }},
          {BackendOption::Resolution, [](BackendConfig& c, SdfOptions&) { c.resolution = 128; }},
          {BackendOption::PeelMode, [](BackendConfig& c, SdfOptions&) { c.vulkan_mode = "layers"; }},
          {BackendOption::Profile, [](BackendConfig& c, SdfOptions&) { c.profile = true; }},
          {BackendOption::MemoryCap, [](BackendConfig& c, SdfOptions&) { c.memory_cap = 1 << 20; }},
          {BackendOption::Accel, [](BackendConfig& c, SdfOptions&) { c.accel = "octree"; }}};
}

}  // namespace

TEST(BackendContract, EveryOptionIsHonouredByOneBackendAndRefusedByTheOther) {
  ASSERT_EQ(setters().size(), backend_option_table().size());
  for (const Setter& s : setters()) {
    BackendConfig config;
    SdfOptions sdf;
    s.set(config, sdf);
    const auto set = options_set(config, sdf);
    ASSERT_EQ(set.size(), 1u) << option_info(s.option).flag;
    EXPECT_EQ(set[0], s.option);
    const BackendKind user = option_info(s.option).used_by;
    const BackendKind other = user == BackendKind::Vulkan ? BackendKind::OpenCL : BackendKind::Vulkan;
    EXPECT_TRUE(honours(user, s.option));
    EXPECT_FALSE(honours(other, s.option));
    EXPECT_NO_THROW(check_backend_options(user, config, sdf));
    try {
      check_backend_options(other, config, sdf);
      ADD_FAILURE() << option_info(s.option).flag << " was accepted by the " << to_string(other) << " backend";
    } catch (const UsageError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(option_info(s.option).flag), std::string::npos) << m;
      EXPECT_NE(m.find(std::string("the ") + to_string(user) + " backend"), std::string::npos) << m;
    }
  }
}

TEST(BackendContract, RaysOnVulkanIsRefusedNamingOpenCl) {
  SdfOptions sdf;
  sdf.rays = 4;
  EXPECT_THROW(check_backend_options(BackendKind::Vulkan, BackendConfig{}, sdf), UsageError);
  sdf.rays = kDefaultRays;
  EXPECT_NO_THROW(check_backend_options(BackendKind::Vulkan, BackendConfig{}, sdf));
}

TEST(BackendContract, BadValuesAreUsageErrors) {
  BackendConfig c;
  c.accel = "kdtree";
  EXPECT_THROW(check_backend_options(BackendKind::OpenCL, c, {}), UsageError);
  c = {};
  c.vulkan_mode = "stack";
  EXPECT_THROW(check_backend_options(BackendKind::Vulkan, c, {}), UsageError);
  SdfOptions s;
  s.cone_degrees = 0.0f;
  EXPECT_THROW(check_backend_options(BackendKind::OpenCL, {}, s), UsageError);
  EXPECT_THROW(parse_backend_kind("metal"), UsageError);
  ComputeRequest r;
  r.smooth_rings = -1;
  EXPECT_THROW(validate(r), UsageError);
  r = {};
  r.load.weld_tolerance = -0.5f;  // negative, and not io::LoadOptions::kDefaultWeld (the default)
  EXPECT_THROW(validate(r), UsageError);
  EXPECT_THROW(parse_shard("2/2"), UsageError);
}

TEST(AutoChoice, ACpuRasterizerLosesToOpenClOnTheCpu) {
  if (!both_built()) GTEST_SKIP() << "needs both backends built";
  const std::vector<DeviceListing> devices{kLavapipe, kPocl};
  const BackendChoice c = choose_backend(BackendConfig{}, SdfOptions{}, devices);
  EXPECT_EQ(c.kind, BackendKind::OpenCL);
  EXPECT_NE(c.reason.find("CPU rasterizer"), std::string::npos) << c.reason;
  EXPECT_NE(c.reason.find("llvmpipe"), std::string::npos) << c.reason;
  // The skeleton's order gives the same on the CPU.
  BackendConfig skeleton;
  skeleton.auto_order = {BackendKind::OpenCL, BackendKind::Vulkan};
  EXPECT_EQ(choose_backend(skeleton, {}, devices).kind, BackendKind::OpenCL);
}

TEST(AutoChoice, AGpuBackendOnAGpu) {
  if (!both_built()) GTEST_SKIP() << "needs both backends built";
  // A Vulkan GPU beside a CPU OpenCL device: Vulkan, whatever the order.
  for (const auto& order : {std::vector{BackendKind::Vulkan, BackendKind::OpenCL}, std::vector{BackendKind::OpenCL, BackendKind::Vulkan}}) {
    BackendConfig c;
    c.auto_order = order;
    const BackendChoice choice = choose_backend(c, {}, std::vector{kPocl, kLavapipe, kVulkanGpu});
    EXPECT_EQ(choice.kind, BackendKind::Vulkan) << choice.reason;
    EXPECT_NE(choice.reason.find("GPU"), std::string::npos) << choice.reason;
  }
  // An OpenCL GPU beside lavapipe: OpenCL.
  EXPECT_EQ(choose_backend({}, {}, std::vector{kLavapipe, kOpenClGpu}).kind, BackendKind::OpenCL);
  // GPUs on both: the order decides, OpenCL first by default (the faster and exact one on the
  // GPU measured).
  const BackendChoice both = choose_backend({}, {}, std::vector{kVulkanGpu, kOpenClGpu});
  EXPECT_EQ(both.kind, BackendKind::OpenCL) << both.reason;
  EXPECT_NE(both.reason.find("on a GPU"), std::string::npos) << both.reason;
  BackendConfig peeling_first;
  peeling_first.auto_order = {BackendKind::Vulkan, BackendKind::OpenCL};
  EXPECT_EQ(choose_backend(peeling_first, {}, std::vector{kVulkanGpu, kOpenClGpu}).kind, BackendKind::Vulkan);
}

TEST(AutoChoice, OptionsNarrowItToTheBackendThatHonoursThem) {
  if (!both_built()) GTEST_SKIP() << "needs both backends built";
  const std::vector<DeviceListing> cpu{kLavapipe, kPocl}, gpu{kVulkanGpu, kPocl};
  BackendConfig views;
  views.views = 64;
  const BackendChoice v = choose_backend(views, {}, cpu);
  EXPECT_EQ(v.kind, BackendKind::Vulkan);
  EXPECT_NE(v.reason.find("--views"), std::string::npos) << v.reason;
  SdfOptions rays;
  rays.rays = 4;
  const BackendChoice r = choose_backend({}, rays, gpu);
  EXPECT_EQ(r.kind, BackendKind::OpenCL);
  EXPECT_NE(r.reason.find("--rays"), std::string::npos) << r.reason;
  EXPECT_THROW(choose_backend(views, rays, cpu), UsageError);
}

TEST(AutoChoice, OnlyUsableDevicesThatTheSelectorNamesCount) {
  if (!both_built()) GTEST_SKIP() << "needs both backends built";
  DeviceListing unusable = kVulkanGpu;
  unusable.usable = false;
  unusable.reason = "no VK_EXT_shader_viewport_index_layer";
  EXPECT_EQ(choose_backend({}, {}, std::vector{unusable, kPocl}).kind, BackendKind::OpenCL);
  BackendConfig c;
  c.device = "llvmpipe";
  EXPECT_EQ(choose_backend(c, {}, std::vector{kLavapipe, kPocl}).kind, BackendKind::Vulkan);
  c.device = "1";  // by index: the GPUs above
  EXPECT_EQ(choose_backend(c, {}, std::vector{kLavapipe, kPocl, kOpenClGpu}).kind, BackendKind::OpenCL);
  EXPECT_THROW(choose_backend({}, {}, std::vector<DeviceListing>{}), DeviceError);
  EXPECT_THROW(choose_backend({}, {}, std::vector{unusable}), DeviceError);
  // A requested backend is not second-guessed.
  c = {};
  c.kind = BackendKind::Vulkan;
  EXPECT_EQ(choose_backend(c, {}, std::vector{kLavapipe, kPocl}).kind, BackendKind::Vulkan);
}

// Every option of a request changes its JSON, and so the batch fingerprint: a rerun with any
// other option recomputes the asset instead of skipping it as complete.
TEST(OptionsJson, EveryOptionChangesTheFingerprint) {
  std::vector<std::function<void(ComputeRequest&)>> changes{
      [](ComputeRequest& r) { r.sdf.rays = 7; },
      [](ComputeRequest& r) { r.sdf.cone_degrees = 90.0f; },
      [](ComputeRequest& r) { r.sdf.domain = SdfDomain::Face; },
      [](ComputeRequest& r) { r.sdf.false_hit = FalseHitRule::Cgal; },
      [](ComputeRequest& r) { r.backend.kind = BackendKind::OpenCL; },
      [](ComputeRequest& r) { r.backend.auto_order = {BackendKind::Vulkan, BackendKind::OpenCL}; },
      [](ComputeRequest& r) { r.backend.device = "1"; },
      [](ComputeRequest& r) { r.backend.views = 64; },
      [](ComputeRequest& r) { r.backend.resolution = 128; },
      [](ComputeRequest& r) { r.backend.vulkan_mode = "layers"; },
      [](ComputeRequest& r) { r.backend.validation = true; },
      [](ComputeRequest& r) { r.backend.profile = true; },
      [](ComputeRequest& r) { r.backend.memory_cap = 1 << 20; },
      [](ComputeRequest& r) { r.backend.accel = "octree"; },
      [](ComputeRequest& r) { r.load.weld_tolerance = 1e-4f; },
      [](ComputeRequest& r) { r.write.color = false; },
      [](ComputeRequest& r) { r.write.normalized = true; },
      [](ComputeRequest& r) { r.write.overlays.push_back({"skeleton", {{0, 0, 0}}, {}, {}}); },
      [](ComputeRequest& r) { r.smooth_rings = 2; },
  };
  BatchOptions base;
  const std::string input = __FILE__;  // any existing file
  std::set<std::string> prints{batch_fingerprint(input, base)};
  std::set<std::string> jsons{options_to_json(base.base)};
  for (std::size_t i = 0; i < changes.size(); ++i) {
    BatchOptions o;
    changes[i](o.base);
    EXPECT_TRUE(jsons.insert(options_to_json(o.base)).second) << "change " << i << " left the options' JSON as is";
    EXPECT_TRUE(prints.insert(batch_fingerprint(input, o)).second) << "change " << i << " left the fingerprint as is";
  }
  // Input and output are not options: the same fingerprint for another output name.
  BatchOptions named;
  named.base.output = "elsewhere.glb";
  EXPECT_EQ(batch_fingerprint(input, named), batch_fingerprint(input, base));
}

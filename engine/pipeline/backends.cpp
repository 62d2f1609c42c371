#include "sdfkit/backends.hpp"

#include "sdfkit/core/error.hpp"

#if SDFKIT_HAS_OPENCL
#include "sdfkit/opencl/opencl_backend.hpp"
#endif
#if SDFKIT_HAS_VULKAN
#include "sdfkit/vulkan/depth_peel.hpp"
#endif

#include <algorithm>
#include <cctype>

namespace sdfkit {

BackendKind parse_backend_kind(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return std::tolower(c); });
  if (n == "auto") return BackendKind::Auto;
  if (n == "vulkan") return BackendKind::Vulkan;
  if (n == "opencl") return BackendKind::OpenCL;
  throw InputError("unknown backend '" + name + "' (expected auto, vulkan or opencl)");
}

const char* to_string(BackendKind kind) {
  switch (kind) {
    case BackendKind::Auto: return "auto";
    case BackendKind::Vulkan: return "vulkan";
    case BackendKind::OpenCL: return "opencl";
  }
  return "?";
}

std::vector<BackendKind> built_backends() {
  std::vector<BackendKind> out;
#if SDFKIT_HAS_VULKAN
  out.push_back(BackendKind::Vulkan);
#endif
#if SDFKIT_HAS_OPENCL
  out.push_back(BackendKind::OpenCL);
#endif
  return out;
}

namespace {

std::unique_ptr<SdfBackend> make_vulkan([[maybe_unused]] const BackendConfig& c) {
#if SDFKIT_HAS_VULKAN
  vk::DepthPeelConfig config;
  config.device = c.device;
  if (c.views > 0) config.views = c.views;
  if (c.resolution > 0) config.resolution = c.resolution;
  if (c.vulkan_mode == "layers") config.mode = vk::PeelMode::Layers;
  else if (c.vulkan_mode == "lists") config.mode = vk::PeelMode::FragmentLists;
  else if (!c.vulkan_mode.empty())
    throw InputError("unknown Vulkan peel mode '" + c.vulkan_mode + "' (expected layers or lists)");
  config.validation = config.validation || c.validation;
  config.profile = c.profile;
  return std::make_unique<vk::DepthPeelBackend>(config);
#else
  throw DeviceError("this sdfkit was built without the Vulkan backend (SDFKIT_WITH_VULKAN=OFF)");
#endif
}

std::unique_ptr<SdfBackend> make_opencl([[maybe_unused]] const BackendConfig& c) {
#if SDFKIT_HAS_OPENCL
  cl::OpenClConfig config;
  config.device = c.device;
  if (c.memory_cap > 0) config.memory_cap = c.memory_cap;
  if (c.accel == "octree")
    config.accel = cl::Accel::Octree;
  else if (c.accel.empty() || c.accel == "bvh")
    config.accel = cl::Accel::Bvh;
  else
    throw InputError("--accel must be bvh or octree, got '" + c.accel + "'");
  return std::make_unique<cl::OpenClBackend>(config);
#else
  throw DeviceError("this sdfkit was built without the OpenCL backend (SDFKIT_WITH_OPENCL=OFF)");
#endif
}

}  // namespace

std::unique_ptr<SdfBackend> make_backend(const BackendConfig& config) {
  switch (config.kind) {
    case BackendKind::Vulkan: return make_vulkan(config);
    case BackendKind::OpenCL: return make_opencl(config);
    case BackendKind::Auto: break;
  }
  std::string reasons;
  for (BackendKind kind : config.auto_order) {
    if (kind == BackendKind::Auto) continue;
    try {
      return kind == BackendKind::Vulkan ? make_vulkan(config) : make_opencl(config);
    } catch (const DeviceError& e) {
      reasons += std::string(reasons.empty() ? "" : "; ") + to_string(kind) + ": " + e.what();
    }
  }
  throw DeviceError("no SDF backend is usable: " + reasons);
}

std::vector<DeviceListing> list_all_devices() {
  std::vector<DeviceListing> out;
#if SDFKIT_HAS_VULKAN
  try {
    for (const auto& d : vk::list_devices_for_depth_peel())
      out.push_back({"vulkan", "#" + std::to_string(d.index) + " " + d.name + " (" + d.type + ", Vulkan " +
                                   d.api_version + ", " + d.driver + ")",
                     d.suitable, d.rejection});
  } catch (const Error& e) {
    out.push_back({"vulkan", "(none)", false, e.what()});
  }
#endif
#if SDFKIT_HAS_OPENCL
  for (const auto& d : cl::list_devices())
    out.push_back({"opencl", "#" + std::to_string(d.index) + " " + d.name + " (" + d.type + ", " +
                                 d.platform + ", " + d.version + ")",
                   true, ""});
#endif
  return out;
}

}  // namespace sdfkit

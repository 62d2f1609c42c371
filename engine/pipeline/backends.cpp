#include "sdfkit/backends.hpp"

#include "sdfkit/core/error.hpp"

#if SDFKIT_HAS_OPENCL
#include "sdfkit/opencl/opencl_backend.hpp"
#endif
#if SDFKIT_HAS_VULKAN
#include "sdfkit/vulkan/depth_peel.hpp"
#endif

#include <algorithm>
#include <array>
#include <cctype>

namespace sdfkit {

BackendKind parse_backend_kind(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return std::tolower(c); });
  if (n == "auto") return BackendKind::Auto;
  if (n == "vulkan") return BackendKind::Vulkan;
  if (n == "opencl") return BackendKind::OpenCL;
  throw UsageError("unknown backend '" + name + "' (expected auto, vulkan or opencl)");
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
  config.accel = c.accel == "octree" ? cl::Accel::Octree : cl::Accel::Bvh;
  return std::make_unique<cl::OpenClBackend>(config);
#else
  throw DeviceError("this sdfkit was built without the OpenCL backend (SDFKIT_WITH_OPENCL=OFF)");
#endif
}

std::unique_ptr<SdfBackend> make_kind(BackendKind kind, const BackendConfig& config) {
  return kind == BackendKind::Vulkan ? make_vulkan(config) : make_opencl(config);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// Whether a --device selector (index or case-insensitive name substring) names this device.
bool selects(const std::string& selector, const DeviceListing& d) {
  if (selector.empty()) return true;
  if (std::all_of(selector.begin(), selector.end(), [](unsigned char c) { return std::isdigit(c) != 0; }))
    return selector.size() < 9 && std::stoi(selector) == d.index;
  return lower(d.name).find(lower(selector)) != std::string::npos;
}

std::string flags_of(const std::vector<BackendOption>& options) {
  std::string out;
  for (BackendOption o : options) out += std::string(out.empty() ? "" : ", ") + option_info(o).flag;
  return out;
}

}  // namespace

std::span<const BackendOptionInfo> backend_option_table() {
  static constexpr std::array<BackendOptionInfo, 7> table{{
      {BackendOption::Rays, "--rays", BackendKind::OpenCL,
       "rays per point of the ray caster (Vulkan's samples are the cameras inside each point's cone: --views)"},
      {BackendOption::Views, "--views", BackendKind::Vulkan, "camera directions of the depth peeling"},
      {BackendOption::Resolution, "--resolution", BackendKind::Vulkan, "framebuffer size of the depth peeling"},
      {BackendOption::PeelMode, "--peel-mode", BackendKind::Vulkan, "layers or fragment lists"},
      {BackendOption::Profile, "--profile", BackendKind::Vulkan, "per-pass GPU timestamps"},
      {BackendOption::MemoryCap, "--memory-cap", BackendKind::OpenCL, "device memory for the ray caster's batches"},
      {BackendOption::Accel, "--accel", BackendKind::OpenCL, "the ray caster's acceleration structure"},
  }};
  return table;
}

const BackendOptionInfo& option_info(BackendOption option) {
  for (const BackendOptionInfo& i : backend_option_table())
    if (i.option == option) return i;
  throw Error("unknown backend option");
}

bool honours(BackendKind backend, BackendOption option) { return option_info(option).used_by == backend; }

std::vector<BackendOption> options_set(const BackendConfig& c, const SdfOptions& sdf) {
  const BackendConfig d;
  std::vector<BackendOption> out;
  if (sdf.rays != SdfOptions{}.rays) out.push_back(BackendOption::Rays);
  if (c.views != d.views) out.push_back(BackendOption::Views);
  if (c.resolution != d.resolution) out.push_back(BackendOption::Resolution);
  if (c.vulkan_mode != d.vulkan_mode) out.push_back(BackendOption::PeelMode);
  if (c.profile != d.profile) out.push_back(BackendOption::Profile);
  if (c.memory_cap != d.memory_cap) out.push_back(BackendOption::MemoryCap);
  if (c.accel != d.accel) out.push_back(BackendOption::Accel);
  return out;
}

void check_backend_options(BackendKind backend, const BackendConfig& c, const SdfOptions& sdf) {
  validate_options(sdf);
  if (!c.vulkan_mode.empty() && c.vulkan_mode != "layers" && c.vulkan_mode != "lists")
    throw UsageError("--peel-mode must be layers or lists, got '" + c.vulkan_mode + "'");
  if (!c.accel.empty() && c.accel != "bvh" && c.accel != "octree")
    throw UsageError("--accel must be bvh or octree, got '" + c.accel + "'");
  if (c.views < 0 || c.resolution < 0) throw UsageError("--views and --resolution must be positive (0 = default)");
  if (backend == BackendKind::Auto) {
    bool vulkan = false, opencl = false;
    for (BackendOption o : options_set(c, sdf)) (honours(BackendKind::Vulkan, o) ? vulkan : opencl) = true;
    if (vulkan && opencl)
      throw UsageError("options of both backends were given: " + flags_of(options_set(c, sdf)) +
                       " (the vulkan backend uses --views --resolution --peel-mode --profile, the opencl "
                       "backend --rays --memory-cap --accel); choose one");
    return;
  }
  for (BackendOption o : options_set(c, sdf))
    if (!honours(backend, o)) {
      const BackendOptionInfo& i = option_info(o);
      throw UsageError(std::string(i.flag) + " is an option of the " + to_string(i.used_by) + " backend (" +
                       i.meaning + "); the " + to_string(backend) + " backend would ignore it");
    }
}

BackendChoice choose_backend(const BackendConfig& config, const SdfOptions& sdf,
                             std::span<const DeviceListing> devices) {
  check_backend_options(config.kind, config, sdf);
  if (config.kind != BackendKind::Auto) return {config.kind, "requested"};
  const std::vector<BackendOption> set = options_set(config, sdf);
  const std::vector<BackendKind> built = built_backends();
  std::vector<BackendKind> candidates;
  for (BackendKind k : config.auto_order)
    if (k != BackendKind::Auto && std::find(built.begin(), built.end(), k) != built.end() &&
        std::find(candidates.begin(), candidates.end(), k) == candidates.end() &&
        std::all_of(set.begin(), set.end(), [&](BackendOption o) { return honours(k, o); }))
      candidates.push_back(k);
  const std::string because_options =
      set.empty() ? std::string() : " (" + flags_of(set) + (set.size() > 1 ? " are options" : " is an option") +
                                        " of the " + to_string(option_info(set[0]).used_by) + " backend)";
  if (candidates.empty())
    throw DeviceError(built.empty() ? std::string("this sdfkit was built without the Vulkan and OpenCL backends")
                                    : "no backend of this build honours " + flags_of(set));
  const auto first_device = [&](BackendKind k, bool gpu_only) -> const DeviceListing* {
    for (const DeviceListing& d : devices)
      if (d.backend == to_string(k) && d.usable && (!gpu_only || d.gpu) && selects(config.device, d)) return &d;
    return nullptr;
  };
  for (BackendKind k : candidates)
    if (const DeviceListing* d = first_device(k, true))
      return {k, std::string(to_string(k)) + " on a GPU (" + d->name + ")" + because_options};
  const DeviceListing* cpu_vulkan = std::find(candidates.begin(), candidates.end(), BackendKind::Vulkan) != candidates.end()
                                        ? first_device(BackendKind::Vulkan, false)
                                        : nullptr;
  if (std::find(candidates.begin(), candidates.end(), BackendKind::OpenCL) != candidates.end())
    if (const DeviceListing* d = first_device(BackendKind::OpenCL, false))
      return {BackendKind::OpenCL,
              "opencl on " + d->name + ": no GPU" +
                  (cpu_vulkan ? ", and the only Vulkan device is a CPU rasterizer (" + cpu_vulkan->name +
                                    "), slower than ray casting on the same cores"
                              : std::string()) +
                  because_options};
  for (BackendKind k : candidates)
    if (const DeviceListing* d = first_device(k, false))
      return {k, std::string(to_string(k)) + " on " + d->name + " (a CPU device; no GPU)" + because_options};
  std::string why;
  for (const DeviceListing& d : devices)
    if (!d.usable) why += "; " + d.backend + " " + d.description + ": " + d.reason;
  throw DeviceError("no SDF backend has a usable device" +
                    (config.device.empty() ? std::string() : " matching --device '" + config.device + "'") +
                    (set.empty() ? std::string() : " among the backends that honour " + flags_of(set)) + why);
}

std::unique_ptr<SdfBackend> make_backend(const BackendConfig& config, const SdfOptions& sdf, BackendChoice* choice) {
  BackendChoice chosen;
  if (config.kind != BackendKind::Auto) {
    check_backend_options(config.kind, config, sdf);
    chosen = {config.kind, "requested"};
    auto backend = make_kind(config.kind, config);
    if (choice) *choice = chosen;
    return backend;
  }
  chosen = choose_backend(config, sdf, list_all_devices());
  try {
    auto backend = make_kind(chosen.kind, config);
    if (choice) *choice = chosen;
    return backend;
  } catch (const DeviceError& e) {
    // The listing said usable, the session did not open: the other backend, if it may run.
    const BackendKind other = chosen.kind == BackendKind::Vulkan ? BackendKind::OpenCL : BackendKind::Vulkan;
    const auto set = options_set(config, sdf);
    const auto built = built_backends();
    if (std::find(built.begin(), built.end(), other) == built.end() ||
        !std::all_of(set.begin(), set.end(), [&](BackendOption o) { return honours(other, o); }))
      throw;
    auto backend = make_kind(other, config);
    if (choice) *choice = {other, std::string(to_string(chosen.kind)) + " failed to open (" + e.what() + ")"};
    return backend;
  }
}

std::vector<DeviceListing> list_all_devices() {
  std::vector<DeviceListing> out;
#if SDFKIT_HAS_VULKAN
  try {
    for (const auto& d : vk::list_devices_for_depth_peel())
      out.push_back({"vulkan",
                     "#" + std::to_string(d.index) + " " + d.name + " (" + d.type + ", Vulkan " + d.api_version +
                         ", " + d.driver + ")",
                     d.suitable, d.rejection, d.name, static_cast<int>(d.index),
                     d.type == "discrete" || d.type == "integrated" || d.type == "virtual"});
  } catch (const Error& e) {
    out.push_back({"vulkan", "(none)", false, e.what(), "", 0, false});
  }
#endif
#if SDFKIT_HAS_OPENCL
  for (const auto& d : cl::list_devices())
    out.push_back({"opencl",
                   "#" + std::to_string(d.index) + " " + d.name + " (" + d.type + ", " + d.platform + ", " +
                       d.version + ")",
                   true, "", d.name, d.index, d.type == "GPU"});
#endif
  return out;
}

}  // namespace sdfkit

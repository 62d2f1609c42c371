#include "sdfkit/vulkan/context.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"
#include "sdfkit/vulkan/memory.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <sstream>

namespace sdfkit::vk {

const char* result_name(VkResult r) {
  switch (r) {
#define SDFKIT_VK_CASE(x) \
  case x: return #x;
    SDFKIT_VK_CASE(VK_SUCCESS)
    SDFKIT_VK_CASE(VK_NOT_READY)
    SDFKIT_VK_CASE(VK_TIMEOUT)
    SDFKIT_VK_CASE(VK_EVENT_SET)
    SDFKIT_VK_CASE(VK_EVENT_RESET)
    SDFKIT_VK_CASE(VK_INCOMPLETE)
    SDFKIT_VK_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    SDFKIT_VK_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    SDFKIT_VK_CASE(VK_ERROR_INITIALIZATION_FAILED)
    SDFKIT_VK_CASE(VK_ERROR_DEVICE_LOST)
    SDFKIT_VK_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    SDFKIT_VK_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    SDFKIT_VK_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    SDFKIT_VK_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    SDFKIT_VK_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    SDFKIT_VK_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    SDFKIT_VK_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    SDFKIT_VK_CASE(VK_ERROR_FRAGMENTED_POOL)
    SDFKIT_VK_CASE(VK_ERROR_UNKNOWN)
    SDFKIT_VK_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
#undef SDFKIT_VK_CASE
    default: return "VK_RESULT_UNKNOWN";
  }
}

void check(VkResult result, const char* what) {
  if (result != VK_SUCCESS)
    throw DeviceError(std::string(what) + " failed (" + result_name(result) + ")");
}

namespace {

const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

std::string version_string(std::uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) +
         "." + std::to_string(VK_API_VERSION_PATCH(v));
}

const char* type_name(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    default: return "other";
  }
}

int type_rank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 4;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 3;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 1;
    default: return 0;
  }
}

bool has_extension(const std::vector<VkExtensionProperties>& exts, const char* name) {
  return std::any_of(exts.begin(), exts.end(),
                     [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

std::vector<VkExtensionProperties> device_extensions(VkPhysicalDevice pd) {
  std::uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> exts(n);
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, exts.data());
  return exts;
}

// Index of a queue family with graphics and compute, or -1.
int find_queue_family(VkPhysicalDevice pd) {
  std::uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
  std::vector<VkQueueFamilyProperties> fams(n);
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, fams.data());
  for (std::uint32_t i = 0; i < n; ++i)
    if ((fams[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) && (fams[i].queueFlags & VK_QUEUE_COMPUTE_BIT))
      return static_cast<int>(i);
  return -1;
}

// Checks `pd` against the engine's baseline and `req`; fills info (suitable, rejection).
DeviceInfo describe(VkPhysicalDevice pd, std::uint32_t index, const DeviceRequirements& req) {
  VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES, nullptr, {}, {}, {}, {}};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, nullptr, {}};
  VkPhysicalDeviceProperties base{};
  vkGetPhysicalDeviceProperties(pd, &base);
  const bool v12 = base.apiVersion >= VK_API_VERSION_1_2;
  if (v12) props.pNext = &driver;
  vkGetPhysicalDeviceProperties2(pd, &props);

  DeviceInfo info;
  info.index = index;
  info.name = base.deviceName;
  info.type = type_name(base.deviceType);
  info.api_version = version_string(base.apiVersion);
  info.driver = v12 ? std::string(driver.driverName) + ": " + driver.driverInfo
                    : "driver version " + std::to_string(base.driverVersion);

  std::vector<std::string> why;
  if (base.apiVersion < VK_API_VERSION_1_1) why.push_back("Vulkan " + info.api_version + " < 1.1");
  if (find_queue_family(pd) < 0) why.push_back("no queue with graphics and compute");
  const auto exts = device_extensions(pd);
  VkPhysicalDeviceDynamicRenderingFeatures dyn{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES, nullptr, VK_FALSE};
  VkPhysicalDeviceSynchronization2Features sync2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES, &dyn, VK_FALSE};
  VkPhysicalDeviceFeatures2 feats{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &sync2, {}};
  const bool v13 = base.apiVersion >= VK_API_VERSION_1_3;
  const bool dyn_ext = has_extension(exts, VK_KHR_DYNAMIC_RENDERING_EXTENSION_NAME);
  const bool sync_ext = has_extension(exts, VK_KHR_SYNCHRONIZATION_2_EXTENSION_NAME);
  if (base.apiVersion >= VK_API_VERSION_1_1) vkGetPhysicalDeviceFeatures2(pd, &feats);
  if (!(v13 || dyn_ext) || !dyn.dynamicRendering) why.push_back("no dynamic rendering");
  if (!(v13 || sync_ext) || !sync2.synchronization2) why.push_back("no synchronization2");
  if (req.shader_output_layer && !has_extension(exts, VK_EXT_SHADER_VIEWPORT_INDEX_LAYER_EXTENSION_NAME))
    why.push_back("no VK_EXT_shader_viewport_index_layer (layered rendering)");
  if (req.geometry_shader && !feats.features.geometryShader)
    why.push_back("no geometryShader feature (gl_PrimitiveID in fragment shaders)");
  VkFormatProperties fp{};
  vkGetPhysicalDeviceFormatProperties(pd, VK_FORMAT_D32_SFLOAT, &fp);
  if (!(fp.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT))
    why.push_back("no 32-bit float depth attachment");
  info.suitable = why.empty();
  for (std::size_t i = 0; i < why.size(); ++i) info.rejection += (i ? "; " : "") + why[i];
  return info;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

VKAPI_ATTR VkBool32 VKAPI_CALL debug_callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data,
                                              void* user) {
  static_cast<Context*>(user)->report_validation_message(static_cast<int>(severity),
                                                         data && data->pMessage ? data->pMessage : "");
  return VK_FALSE;
}

bool layer_available(const char* name) {
  std::uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  return std::any_of(layers.begin(), layers.end(),
                     [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

UniqueInstance make_instance(bool validation, const void* pnext) {
  std::uint32_t loader_version = VK_API_VERSION_1_1;
  vkEnumerateInstanceVersion(&loader_version);
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO, nullptr, "sdfkit", 1, "sdfkit", 1,
                        std::min<std::uint32_t>(loader_version, VK_API_VERSION_1_3)};
  std::vector<const char*> layers, exts;
  if (validation) {
    layers.push_back(kValidationLayer);
    exts.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, pnext, 0, &app,
                          static_cast<std::uint32_t>(layers.size()), layers.data(),
                          static_cast<std::uint32_t>(exts.size()), exts.data()};
  VkInstance inst = VK_NULL_HANDLE;
  const VkResult r = vkCreateInstance(&ci, nullptr, &inst);
  if (r != VK_SUCCESS)
    throw DeviceError(std::string("could not create a Vulkan instance (") + result_name(r) +
                      "); is a Vulkan driver installed (Mesa lavapipe: mesa-vulkan-drivers)?");
  return UniqueInstance(inst);
}

std::vector<VkPhysicalDevice> physical_devices(VkInstance inst) {
  std::uint32_t n = 0;
  vkEnumeratePhysicalDevices(inst, &n, nullptr);
  std::vector<VkPhysicalDevice> pds(n);
  vkEnumeratePhysicalDevices(inst, &n, pds.data());
  return pds;
}

}  // namespace

bool validation_requested_by_environment() {
#ifndef NDEBUG
  return true;
#else
  const char* v = std::getenv("SDFKIT_VK_VALIDATION");
  return v && std::string(v) == "1";
#endif
}

std::vector<DeviceInfo> list_devices(const DeviceRequirements& requirements) {
  UniqueInstance inst = make_instance(false, nullptr);
  std::vector<DeviceInfo> out;
  const auto pds = physical_devices(inst.get());
  for (std::uint32_t i = 0; i < pds.size(); ++i) out.push_back(describe(pds[i], i, requirements));
  return out;
}

Context::Context(const ContextConfig& config) {
  create_instance(config.validation || validation_requested_by_environment());
  pick_device(config);
  create_device(config.requirements);
  allocator_ = std::make_unique<Allocator>(physical_, device_.get());
}

Context::~Context() {
  if (device_.get() != VK_NULL_HANDLE) vkDeviceWaitIdle(device_.get());
  allocator_.reset();
  command_pool_.reset();
  device_ = UniqueDevice();
  if (messenger_ != VK_NULL_HANDLE) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_.get(), "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_.get(), messenger_, nullptr);
  }
}

void Context::create_instance(bool validation) {
  if (validation && !layer_available(kValidationLayer))
    throw DeviceError(std::string("Vulkan validation was requested but ") + kValidationLayer +
                      " is not installed (Debian package vulkan-validationlayers)");
  validation_ = validation;
  VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  mci.pfnUserCallback = debug_callback;
  mci.pUserData = this;
  // Chained into the instance so that instance creation/destruction is checked too.
  instance_ = make_instance(validation, validation ? &mci : nullptr);
  if (validation) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_.get(), "vkCreateDebugUtilsMessengerEXT"));
    if (!create) throw DeviceError("the validation layer provides no vkCreateDebugUtilsMessengerEXT");
    check(create(instance_.get(), &mci, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
  }
}

void Context::pick_device(const ContextConfig& config) {
  const auto pds = physical_devices(instance_.get());
  std::vector<DeviceInfo> infos;
  for (std::uint32_t i = 0; i < pds.size(); ++i) infos.push_back(describe(pds[i], i, config.requirements));
  auto listing = [&] {
    std::string s;
    for (const auto& d : infos)
      s += "\n  [" + std::to_string(d.index) + "] " + d.name + " (" + d.type + ", Vulkan " +
           d.api_version + "): " + (d.suitable ? "suitable" : "rejected: " + d.rejection);
    return s.empty() ? std::string("\n  (no Vulkan devices found)") : s;
  };

  std::string wanted = config.device;
  if (wanted.empty())
    if (const char* env = std::getenv("SDFKIT_VK_DEVICE")) wanted = env;

  int chosen = -1;
  if (!wanted.empty()) {
    const bool numeric = std::all_of(wanted.begin(), wanted.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
    for (const auto& d : infos)
      if (numeric ? d.index == static_cast<std::uint32_t>(std::stoul(wanted))
                  : lower(d.name).find(lower(wanted)) != std::string::npos) {
        chosen = static_cast<int>(d.index);
        break;
      }
    if (chosen < 0) throw DeviceError("no Vulkan device matches '" + wanted + "':" + listing());
    if (!infos[chosen].suitable)
      throw DeviceError("the Vulkan device '" + infos[chosen].name + "' cannot be used (" +
                        infos[chosen].rejection + "):" + listing());
  } else {
    int best_rank = -1;
    for (const auto& d : infos) {
      if (!d.suitable) continue;
      VkPhysicalDeviceProperties p{};
      vkGetPhysicalDeviceProperties(pds[d.index], &p);
      if (type_rank(p.deviceType) > best_rank) {
        best_rank = type_rank(p.deviceType);
        chosen = static_cast<int>(d.index);
      }
    }
    if (chosen < 0) throw DeviceError("no suitable Vulkan device:" + listing());
  }
  physical_ = pds[chosen];
  info_ = infos[chosen];
}

void Context::create_device(const DeviceRequirements& req) {
  VkPhysicalDeviceProperties props{};
  vkGetPhysicalDeviceProperties(physical_, &props);
  limits_ = props.limits;
  VkPhysicalDeviceFeatures avail{};
  vkGetPhysicalDeviceFeatures(physical_, &avail);
  queue_family_ = static_cast<std::uint32_t>(find_queue_family(physical_));
  std::uint32_t nf = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &nf, nullptr);
  std::vector<VkQueueFamilyProperties> fams(nf);
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &nf, fams.data());

  const auto exts = device_extensions(physical_);
  std::vector<const char*> enable;
  const bool v13 = props.apiVersion >= VK_API_VERSION_1_3;
  const bool v12 = props.apiVersion >= VK_API_VERSION_1_2;
  if (!v13) {
    enable.push_back(VK_KHR_DYNAMIC_RENDERING_EXTENSION_NAME);
    enable.push_back(VK_KHR_SYNCHRONIZATION_2_EXTENSION_NAME);
    if (!v12) {
      enable.push_back(VK_KHR_DEPTH_STENCIL_RESOLVE_EXTENSION_NAME);
      enable.push_back(VK_KHR_CREATE_RENDERPASS_2_EXTENSION_NAME);
    }
  }
  caps_.shader_output_layer = has_extension(exts, VK_EXT_SHADER_VIEWPORT_INDEX_LAYER_EXTENSION_NAME);
  if (caps_.shader_output_layer) enable.push_back(VK_EXT_SHADER_VIEWPORT_INDEX_LAYER_EXTENSION_NAME);
  (void)req;

  VkPhysicalDeviceDynamicRenderingFeatures dyn{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES, nullptr, VK_TRUE};
  VkPhysicalDeviceSynchronization2Features sync2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES, &dyn, VK_TRUE};
  VkPhysicalDeviceFeatures2 feats{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &sync2, {}};
  feats.features.geometryShader = avail.geometryShader;
  feats.features.fragmentStoresAndAtomics = avail.fragmentStoresAndAtomics;
  feats.features.vertexPipelineStoresAndAtomics = avail.vertexPipelineStoresAndAtomics;

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO, nullptr, 0, queue_family_, 1, &priority};
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.pNext = &feats;
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = static_cast<std::uint32_t>(enable.size());
  dci.ppEnabledExtensionNames = enable.data();
  VkDevice dev = VK_NULL_HANDLE;
  check(vkCreateDevice(physical_, &dci, nullptr, &dev), "creating the Vulkan device");
  device_ = UniqueDevice(dev);
  vkGetDeviceQueue(dev, queue_family_, 0, &queue_);

  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO, nullptr,
                              VK_COMMAND_POOL_CREATE_TRANSIENT_BIT | VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT,
                              queue_family_};
  VkCommandPool pool = VK_NULL_HANDLE;
  check(vkCreateCommandPool(dev, &pci, nullptr, &pool), "creating a command pool");
  command_pool_ = UniqueCommandPool(dev, pool);

  auto load = [&](const char* core, const char* khr) {
    PFN_vkVoidFunction f = v13 ? vkGetDeviceProcAddr(dev, core) : nullptr;
    if (!f) f = vkGetDeviceProcAddr(dev, khr);
    if (!f) throw DeviceError(std::string("the Vulkan device provides no ") + core);
    return f;
  };
  functions_.cmd_pipeline_barrier2 =
      reinterpret_cast<PFN_vkCmdPipelineBarrier2>(load("vkCmdPipelineBarrier2", "vkCmdPipelineBarrier2KHR"));
  functions_.cmd_begin_rendering =
      reinterpret_cast<PFN_vkCmdBeginRendering>(load("vkCmdBeginRendering", "vkCmdBeginRenderingKHR"));
  functions_.cmd_end_rendering =
      reinterpret_cast<PFN_vkCmdEndRendering>(load("vkCmdEndRendering", "vkCmdEndRenderingKHR"));
  functions_.cmd_write_timestamp2 =
      reinterpret_cast<PFN_vkCmdWriteTimestamp2>(load("vkCmdWriteTimestamp2", "vkCmdWriteTimestamp2KHR"));

  caps_.timestamps = fams[queue_family_].timestampValidBits > 0 && props.limits.timestampPeriod > 0.0f;
  caps_.timestamp_period_ns = props.limits.timestampPeriod;
  caps_.geometry_shader = avail.geometryShader;
  caps_.max_framebuffer_layers = props.limits.maxFramebufferLayers;
  caps_.max_image_dimension_2d = props.limits.maxImageDimension2D;
  caps_.max_storage_buffer_range = props.limits.maxStorageBufferRange;
}

std::size_t Context::validation_message_count() const {
  std::lock_guard lock(messages_mutex_);
  return messages_.size();
}

std::vector<std::string> Context::validation_messages() const {
  std::lock_guard lock(messages_mutex_);
  return messages_;
}

void Context::clear_validation_messages() {
  std::lock_guard lock(messages_mutex_);
  messages_.clear();
}

void Context::report_validation_message(int severity, const char* message) {
  const bool error = severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  std::string m = std::string(error ? "Vulkan validation error: " : "Vulkan validation warning: ") + message;
  log(error ? LogLevel::Error : LogLevel::Warning, m);
  std::lock_guard lock(messages_mutex_);
  messages_.push_back(std::move(m));
}

void Context::submit_and_wait(const std::function<void(VkCommandBuffer)>& record) {
  VkDevice dev = device_.get();
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr,
                                 command_pool_.get(), VK_COMMAND_BUFFER_LEVEL_PRIMARY, 1};
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  check(vkAllocateCommandBuffers(dev, &ai, &cmd), "allocating a command buffer");
  // Freed on every exit path.
  struct Free {
    VkDevice d;
    VkCommandPool p;
    VkCommandBuffer c;
    ~Free() { vkFreeCommandBuffers(d, p, 1, &c); }
  } free_cmd{dev, command_pool_.get(), cmd};

  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO, nullptr,
                              VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT, nullptr};
  check(vkBeginCommandBuffer(cmd, &bi), "beginning a command buffer");
  record(cmd);
  check(vkEndCommandBuffer(cmd), "ending a command buffer");

  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO, nullptr, 0};
  VkFence f = VK_NULL_HANDLE;
  check(vkCreateFence(dev, &fci, nullptr, &f), "creating a fence");
  UniqueFence fence(dev, f);
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  check(vkQueueSubmit(queue_, 1, &si, f), "submitting commands");
  check(vkWaitForFences(dev, 1, &f, VK_TRUE, UINT64_MAX), "waiting for the device");
}

}  // namespace sdfkit::vk

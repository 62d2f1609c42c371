#pragma once
// A headless Vulkan context: instance (no surface extensions), optional validation layer with one
// debug messenger, the physical device chosen by required features, one graphics+compute queue,
// a command pool, and the memory sub-allocator. Not movable: the debug messenger points at it.
// Keep it in a std::unique_ptr when it must move.

#include "sdfkit/vulkan/handles.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace sdfkit::vk {

class Allocator;

// What the caller needs from a device beyond the engine's baseline (Vulkan 1.1, a
// graphics+compute queue, dynamic rendering, synchronization2).
struct DeviceRequirements {
  bool shader_output_layer = false;  // gl_Layer written by the vertex shader (layered rendering)
  bool geometry_shader = false;      // also what gl_PrimitiveID in fragment shaders needs
};

struct ContextConfig {
  // Index (as listed by list_devices) or case-insensitive name substring; empty = the
  // environment variable SDFKIT_VK_DEVICE, else the best suitable device (discrete, integrated,
  // virtual, CPU, in that order).
  std::string device;
  // Also on in debug builds and when SDFKIT_VK_VALIDATION=1.
  bool validation = false;
  DeviceRequirements requirements;
};

// One physical device as seen by the engine; `suitable` false says why in `rejection`.
struct DeviceInfo {
  std::uint32_t index = 0;
  std::string name;
  std::string type;         // "discrete", "integrated", "virtual", "cpu", "other"
  std::string api_version;  // "1.3.230"
  std::string driver;       // "llvmpipe: Mesa 22.3.6 (LLVM 15.0.6)"
  bool suitable = false;
  std::string rejection;
};

// Optional features found on the chosen device.
struct Capabilities {
  bool timestamps = false;          // per-pass GPU timing possible
  float timestamp_period_ns = 1.0f; // nanoseconds per timestamp tick
  bool shader_output_layer = false; // VK_EXT_shader_viewport_index_layer enabled
  bool geometry_shader = false;
  std::uint32_t max_framebuffer_layers = 1;
  std::uint32_t max_image_dimension_2d = 0;
  VkDeviceSize max_storage_buffer_range = 0;
};

// Entry points of synchronization2, dynamic rendering and timestamps, core (1.3) or KHR.
struct DeviceFunctions {
  PFN_vkCmdPipelineBarrier2 cmd_pipeline_barrier2 = nullptr;
  PFN_vkCmdBeginRendering cmd_begin_rendering = nullptr;
  PFN_vkCmdEndRendering cmd_end_rendering = nullptr;
  PFN_vkCmdWriteTimestamp2 cmd_write_timestamp2 = nullptr;
};

// Every physical device with its suitability for `requirements` (creates a temporary instance).
std::vector<DeviceInfo> list_devices(const DeviceRequirements& requirements = {});

class Context {
public:
  explicit Context(const ContextConfig& config = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_.get(); }
  VkPhysicalDevice physical_device() const { return physical_; }
  VkDevice device() const { return device_.get(); }
  VkQueue queue() const { return queue_; }
  std::uint32_t queue_family() const { return queue_family_; }
  const DeviceInfo& info() const { return info_; }
  const Capabilities& capabilities() const { return caps_; }
  const VkPhysicalDeviceLimits& limits() const { return limits_; }
  Allocator& allocator() { return *allocator_; }
  const DeviceFunctions& functions() const { return functions_; }

  // Validation: warnings and errors reported by the layer since the last clear (tests assert
  // the count is zero).
  bool validation_enabled() const { return validation_; }
  std::size_t validation_message_count() const;
  std::vector<std::string> validation_messages() const;
  void clear_validation_messages();

  // Records with `record` into a fresh primary command buffer, submits it to the queue and
  // waits for it to finish.
  void submit_and_wait(const std::function<void(VkCommandBuffer)>& record);

  // Called by the debug messenger.
  void report_validation_message(int severity, const char* message);

private:
  void create_instance(bool validation);
  void pick_device(const ContextConfig& config);
  void create_device(const DeviceRequirements& requirements);

  bool validation_ = false;
  UniqueInstance instance_;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;  // destroyed in ~Context
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  DeviceInfo info_;
  Capabilities caps_;
  DeviceFunctions functions_;
  VkPhysicalDeviceLimits limits_{};
  UniqueDevice device_;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t queue_family_ = 0;
  UniqueCommandPool command_pool_;
  std::unique_ptr<Allocator> allocator_;

  mutable std::mutex messages_mutex_;
  std::vector<std::string> messages_;
};

// True when validation is on by default (debug build or SDFKIT_VK_VALIDATION=1).
bool validation_requested_by_environment();

}  // namespace sdfkit::vk

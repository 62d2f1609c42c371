#pragma once
// Move-only owners of Vulkan handles. Each type destroys exactly one handle with the function
// that matches it; destruction order is the declaration order of the owning class's members
// (reversed), so it stays visible in the code.

#include <vulkan/vulkan.h>

#include <string>
#include <utility>

namespace sdfkit::vk {

// "VK_ERROR_OUT_OF_DEVICE_MEMORY" for a VkResult.
const char* result_name(VkResult result);

// Throws DeviceError("<what>: <VkResult name>") when result is not VK_SUCCESS.
void check(VkResult result, const char* what);

// A handle created from a VkDevice and destroyed by `Destroy(device, handle, nullptr)`.
template <typename T, void (*Destroy)(VkDevice, T, const VkAllocationCallbacks*)>
class DeviceHandle {
public:
  DeviceHandle() = default;
  DeviceHandle(VkDevice device, T handle) : device_(device), handle_(handle) {}
  ~DeviceHandle() { reset(); }
  DeviceHandle(DeviceHandle&& o) noexcept
      : device_(o.device_), handle_(std::exchange(o.handle_, VK_NULL_HANDLE)) {}
  DeviceHandle& operator=(DeviceHandle&& o) noexcept {
    if (this != &o) {
      reset();
      device_ = o.device_;
      handle_ = std::exchange(o.handle_, VK_NULL_HANDLE);
    }
    return *this;
  }
  DeviceHandle(const DeviceHandle&) = delete;
  DeviceHandle& operator=(const DeviceHandle&) = delete;

  T get() const { return handle_; }
  explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }
  void reset() {
    if (handle_ != VK_NULL_HANDLE) Destroy(device_, handle_, nullptr);
    handle_ = VK_NULL_HANDLE;
  }

private:
  VkDevice device_ = VK_NULL_HANDLE;
  T handle_ = VK_NULL_HANDLE;
};

using UniqueBuffer = DeviceHandle<VkBuffer, vkDestroyBuffer>;
using UniqueImage = DeviceHandle<VkImage, vkDestroyImage>;
using UniqueImageView = DeviceHandle<VkImageView, vkDestroyImageView>;
using UniqueSampler = DeviceHandle<VkSampler, vkDestroySampler>;
using UniqueMemory = DeviceHandle<VkDeviceMemory, vkFreeMemory>;
using UniqueShaderModule = DeviceHandle<VkShaderModule, vkDestroyShaderModule>;
using UniquePipeline = DeviceHandle<VkPipeline, vkDestroyPipeline>;
using UniquePipelineLayout = DeviceHandle<VkPipelineLayout, vkDestroyPipelineLayout>;
using UniqueDescriptorSetLayout = DeviceHandle<VkDescriptorSetLayout, vkDestroyDescriptorSetLayout>;
using UniqueDescriptorPool = DeviceHandle<VkDescriptorPool, vkDestroyDescriptorPool>;
using UniqueCommandPool = DeviceHandle<VkCommandPool, vkDestroyCommandPool>;
using UniqueFence = DeviceHandle<VkFence, vkDestroyFence>;
using UniqueQueryPool = DeviceHandle<VkQueryPool, vkDestroyQueryPool>;

// The device itself (destroyed with vkDestroyDevice).
class UniqueDevice {
public:
  UniqueDevice() = default;
  explicit UniqueDevice(VkDevice d) : device_(d) {}
  ~UniqueDevice() {
    if (device_ != VK_NULL_HANDLE) vkDestroyDevice(device_, nullptr);
  }
  UniqueDevice(UniqueDevice&& o) noexcept : device_(std::exchange(o.device_, VK_NULL_HANDLE)) {}
  UniqueDevice& operator=(UniqueDevice&& o) noexcept {
    if (this != &o) {
      if (device_ != VK_NULL_HANDLE) vkDestroyDevice(device_, nullptr);
      device_ = std::exchange(o.device_, VK_NULL_HANDLE);
    }
    return *this;
  }
  UniqueDevice(const UniqueDevice&) = delete;
  UniqueDevice& operator=(const UniqueDevice&) = delete;
  VkDevice get() const { return device_; }

private:
  VkDevice device_ = VK_NULL_HANDLE;
};

// The instance (destroyed with vkDestroyInstance).
class UniqueInstance {
public:
  UniqueInstance() = default;
  explicit UniqueInstance(VkInstance i) : instance_(i) {}
  ~UniqueInstance() {
    if (instance_ != VK_NULL_HANDLE) vkDestroyInstance(instance_, nullptr);
  }
  UniqueInstance(UniqueInstance&& o) noexcept
      : instance_(std::exchange(o.instance_, VK_NULL_HANDLE)) {}
  UniqueInstance& operator=(UniqueInstance&& o) noexcept {
    if (this != &o) {
      if (instance_ != VK_NULL_HANDLE) vkDestroyInstance(instance_, nullptr);
      instance_ = std::exchange(o.instance_, VK_NULL_HANDLE);
    }
    return *this;
  }
  UniqueInstance(const UniqueInstance&) = delete;
  UniqueInstance& operator=(const UniqueInstance&) = delete;
  VkInstance get() const { return instance_; }

private:
  VkInstance instance_ = VK_NULL_HANDLE;
};

}  // namespace sdfkit::vk

// The engine on a real device (lavapipe in CI): context, allocator, embedded SPIR-V, one-time
// submission, validation messages counted.

#include "test_shaders.hpp"
#include "vk_test_util.hpp"

#include "sdfkit/vulkan/depth_peel.hpp"
#include "sdfkit/vulkan/memory.hpp"
#include "sdfkit/vulkan/pipeline.hpp"

#include <cstring>

namespace sdfkit::vk {
namespace {

TEST(VulkanContext, ListsDevicesWithReasons) {
  std::vector<DeviceInfo> devices;
  try {
    devices = list_devices_for_depth_peel();
  } catch (const DeviceError&) {
    if (!test::allow_no_device()) throw;
  }
  if (devices.empty() && test::allow_no_device()) GTEST_SKIP() << "no Vulkan device";
  ASSERT_FALSE(devices.empty());
  for (const auto& d : devices) {
    EXPECT_FALSE(d.name.empty());
    EXPECT_EQ(d.suitable, d.rejection.empty()) << d.name << ": " << d.rejection;
  }
}

TEST(VulkanContext, UnknownDeviceNameIsAnErrorListingDevices) {
  ContextConfig cfg;
  cfg.device = "no-such-gpu-xyz";
  try {
    Context ctx(cfg);
    FAIL() << "expected DeviceError";
  } catch (const DeviceError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no-such-gpu-xyz"), std::string::npos) << what;
    if (!test::allow_no_device()) {
      EXPECT_NE(what.find("[0]"), std::string::npos) << what;
    }
  }
}

TEST(VulkanContext, ValidationIsOnAndMessagesAreCounted) {
  auto ctx = test::make_test_context();
  if (!ctx) GTEST_SKIP() << "no Vulkan device";
  EXPECT_TRUE(ctx->validation_enabled());
  // A deliberate misuse: a buffer of size 0 is invalid usage (VUID-VkBufferCreateInfo-size-00912).
  VkBufferCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  ci.size = 0;
  ci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VkBuffer b = VK_NULL_HANDLE;
  vkCreateBuffer(ctx->device(), &ci, nullptr, &b);
  if (b != VK_NULL_HANDLE) vkDestroyBuffer(ctx->device(), b, nullptr);
  EXPECT_GE(ctx->validation_message_count(), 1u);
  ctx->clear_validation_messages();
}

TEST(VulkanContext, AllocatorSubAllocatesAndReusesFreedRanges) {
  auto ctx = test::make_test_context();
  if (!ctx) GTEST_SKIP() << "no Vulkan device";
  Allocator& a = ctx->allocator();
  {
    Buffer b1 = create_buffer(*ctx, 1000, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Upload);
    Buffer b2 = create_buffer(*ctx, 3000, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Upload);
    EXPECT_EQ(b1.memory.memory(), b2.memory.memory());  // same block
    EXPECT_GE(b2.memory.offset(), b1.memory.offset() + 1000);
    EXPECT_NE(b1.mapped(), nullptr);
  }
  EXPECT_EQ(a.bytes_in_use(), 0u);
  const std::size_t blocks = a.block_count();
  Buffer b3 = create_buffer(*ctx, 2000, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Upload);
  EXPECT_EQ(a.block_count(), blocks);
  EXPECT_EQ(b3.memory.offset(), 0u);  // freed ranges were merged back
  SDFKIT_EXPECT_NO_VALIDATION_MESSAGES(*ctx);
}

TEST(VulkanContext, EmbeddedComputeShaderRunsValidationClean) {
  auto ctx = test::make_test_context();
  if (!ctx) GTEST_SKIP() << "no Vulkan device";
  const std::uint32_t n = 1000;
  Buffer in = create_buffer(*ctx, n * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Upload);
  Buffer out = create_buffer(*ctx, n * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Readback);
  auto* src = static_cast<float*>(in.mapped());
  for (std::uint32_t i = 0; i < n; ++i) src[i] = 0.5f * static_cast<float>(i);
  const VkDescriptorType bindings[] = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
  Pipeline p = create_compute_pipeline(*ctx, test::test_spirv("test_fill.comp"), bindings, sizeof(std::uint32_t),
                                       "test_fill.comp");
  UniqueDescriptorPool pool = create_descriptor_pool(ctx->device(), bindings, 1);
  VkDescriptorSet set = allocate_set(ctx->device(), pool.get(), p.set_layout.get());
  const DescriptorWrite writes[] = {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, in.get()},
                                    {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, out.get()}};
  write_set(ctx->device(), set, writes);
  ctx->submit_and_wait([&](VkCommandBuffer cmd) {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.get());
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout.get(), 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(cmd, p.layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, 4, &n);
    vkCmdDispatch(cmd, (n + 63) / 64, 1, 1);
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER, nullptr, VK_ACCESS_SHADER_WRITE_BIT, VK_ACCESS_HOST_READ_BIT};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0,
                         nullptr, 0, nullptr);
  });
  const auto* dst = static_cast<const float*>(out.mapped());
  for (std::uint32_t i = 0; i < n; ++i) ASSERT_EQ(dst[i], static_cast<float>(i) * 2.0f) << i;
  SDFKIT_EXPECT_NO_VALIDATION_MESSAGES(*ctx);
}

}  // namespace
}  // namespace sdfkit::vk

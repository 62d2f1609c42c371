// The shared definition's false-hit rules, cone test and sample store as the depth-peeling
// passes evaluate them on the device (peel_samples.glsl, through tests/vulkan/shaders/
// definition_probe.comp), held to the C++ definition for both rules.
#include "test_shaders.hpp"
#include "vk_test_util.hpp"

#include "definition_cases.hpp"

#include "sdfkit/vulkan/memory.hpp"
#include "sdfkit/vulkan/pipeline.hpp"

#include <glm/vec2.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace sdfkit::vk {
namespace {

TEST(VulkanDefinition, FalseHitRulesConeTestAndSampleStoreEqualTheDefinition) {
  auto ctx = test::make_test_context();
  if (!ctx) GTEST_SKIP() << "no Vulkan device";
  const std::vector<glm::vec4> cases = test::definition_cases();
  const auto n = static_cast<std::uint32_t>(cases.size() / 3);
  Buffer in = create_buffer(*ctx, cases.size() * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Upload);
  std::memcpy(in.mapped(), cases.data(), cases.size() * sizeof(glm::vec4));
  Buffer counts = create_buffer(*ctx, 2 * n * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Readback);
  Buffer samples = create_buffer(*ctx, 2 * n * 8, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Readback);
  Buffer bits = create_buffer(*ctx, n * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Readback);
  std::memset(counts.mapped(), 0, 2 * n * 4);
  std::memset(samples.mapped(), 0, 2 * n * 8);

  const VkDescriptorType b[] = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
  Pipeline p = create_compute_pipeline(*ctx, test::test_spirv("definition_probe.comp"), b, 4, "definition_probe.comp");
  UniqueDescriptorPool pool = create_descriptor_pool(ctx->device(), b, 1);
  VkDescriptorSet set = allocate_set(ctx->device(), pool.get(), p.set_layout.get());
  const DescriptorWrite w[] = {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, in.get()},
                               {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, counts.get()},
                               {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, samples.get()},
                               {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, bits.get()}};
  write_set(ctx->device(), set, w);
  ctx->submit_and_wait([&](VkCommandBuffer cmd) {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.get());
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout.get(), 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(cmd, p.layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, 4, &n);
    vkCmdDispatch(cmd, (n + 63) / 64, 1, 1);
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER, nullptr, VK_ACCESS_SHADER_WRITE_BIT, VK_ACCESS_HOST_READ_BIT};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0,
                         nullptr, 0, nullptr);
  });

  const auto* got_bits = static_cast<const std::uint32_t*>(bits.mapped());
  const auto* got_counts = static_cast<const std::uint32_t*>(counts.mapped());
  const auto* got_samples = static_cast<const glm::vec2*>(samples.mapped());
  std::uint32_t seen = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t want = test::definition_bits(cases, i);
    seen |= (want & 3u) == 1u ? 1u : (want & 3u) == 2u ? 2u : 0u;
    ASSERT_EQ(got_bits[i], want) << "case " << i;
    // The store keeps exactly the hits its rule accepts, with length 1 and the view's angle.
    for (std::uint32_t rule = 0; rule < 2; ++rule) {
      const bool keeps = (want >> rule) & 1u;
      ASSERT_EQ(got_counts[2 * i + rule], keeps ? 1u : 0u) << "case " << i << ", rule " << rule;
      if (!keeps) continue;
      const float cos_theta = glm::dot(-glm::vec3(cases[3 * i]), glm::vec3(cases[3 * i + 1]));
      EXPECT_FLOAT_EQ(got_samples[2 * i + rule].x, 1.0f) << "case " << i;
      EXPECT_NEAR(got_samples[2 * i + rule].y, std::acos(std::clamp(cos_theta, -1.0f, 1.0f)), 5e-4f)
          << "case " << i;  // lavapipe's acos: within 2e-4 rad
    }
  }
  EXPECT_EQ(seen, 3u) << "the cases must include hits only one rule keeps, each way";
  SDFKIT_EXPECT_NO_VALIDATION_MESSAGES(*ctx);
}

}  // namespace
}  // namespace sdfkit::vk

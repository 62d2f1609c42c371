// A small real render graph on the device: a graphics pass draws into a transient image, a
// compute pass samples it into an imported buffer; the graph derives every barrier.

#include "test_shaders.hpp"
#include "vk_test_util.hpp"

#include "sdfkit/vulkan/memory.hpp"
#include "sdfkit/vulkan/pipeline.hpp"
#include "sdfkit/vulkan/render_graph.hpp"

namespace sdfkit::vk {
namespace {

TEST(VulkanRenderGraph, DrawThenSampleOnDevice) {
  auto ctx = test::make_test_context();
  if (!ctx) GTEST_SKIP() << "no Vulkan device";
  VkDevice dev = ctx->device();
  const std::uint32_t w = 16;

  GraphicsPipelineDescription gd;
  gd.vertex_shader = "test_triangle.vert";
  gd.fragment_shader = "test_constant.frag";
  gd.vertex_spirv = test::test_spirv("test_triangle.vert");
  gd.fragment_spirv = test::test_spirv("test_constant.frag");
  gd.push_bytes = 4;
  gd.color_formats = {VK_FORMAT_R32_SFLOAT};
  Pipeline draw = create_graphics_pipeline(*ctx, gd);
  const VkDescriptorType cb[] = {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
  Pipeline copy = create_compute_pipeline(*ctx, test::test_spirv("test_sample.comp"), cb, 0, "test_sample.comp");
  UniqueDescriptorPool pool = create_descriptor_pool(dev, cb, 1);
  VkDescriptorSet set = allocate_set(dev, pool.get(), copy.set_layout.get());
  UniqueSampler sampler = create_nearest_sampler(dev);

  Buffer out = create_buffer(*ctx, w * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Readback);
  std::fill_n(static_cast<float*>(out.mapped()), w, 0.0f);
  TransientPool transients(*ctx);

  for (int run = 0; run < 2; ++run) {  // the second run reuses the pooled image
    RenderGraph g;
    auto img = g.create_image("color", {VK_FORMAT_R32_SFLOAT, w, w, 1});
    ExternalBuffer eb;
    eb.buffer = out.get();
    eb.initial = {VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED};
    auto buf = g.import_buffer("row", w * 4, eb);
    auto unused = g.create_image("unused", {VK_FORMAT_R32_SFLOAT, w, w, 1});
    auto p1 = g.add_pass("draw", PassKind::Graphics);
    img = p1.color(img, LoadOp::Clear, VkClearColorValue{{-1.0f, 0, 0, 0}});
    p1.execute([&](PassContext& pc) {
      const float v = 3.0f;
      vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, draw.get());
      vkCmdPushConstants(pc.cmd, draw.layout.get(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, 4, &v);
      vkCmdDraw(pc.cmd, 3, 1, 0, 0);
    });
    auto dead = g.add_pass("dead", PassKind::Graphics);  // culled: nobody reads `unused`
    unused = dead.color(unused, LoadOp::Clear);
    auto p2 = g.add_pass("copy", PassKind::Compute);
    p2.sampled(img);
    buf = p2.storage_read_write(buf);
    p2.execute([&, img](PassContext& pc) {
      const DescriptorWrite writes[] = {
          {0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_NULL_HANDLE, pc.view(img),
           VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, sampler.get()},
          {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, out.get()}};
      write_set(dev, set, writes);
      vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, copy.get());
      vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, copy.layout.get(), 0, 1, &set, 0, nullptr);
      vkCmdDispatch(pc.cmd, 1, 1, 1);
    });
    // The host reads the buffer after execute() has waited for the device.
    const CompiledGraph c = g.compile();
    EXPECT_EQ(c.culled, std::vector<std::string>{"dead"});
    const auto timings = execute(*ctx, c, transients, {.profile = true});
    if (ctx->capabilities().timestamps) {
      EXPECT_EQ(timings.size(), 2u);
    }
    EXPECT_EQ(transients.image_count(), 1u);
  }
  const auto* row = static_cast<const float*>(out.mapped());
  for (std::uint32_t x = 0; x < w; ++x) EXPECT_EQ(row[x], x < w / 2 ? 6.0f : -2.0f) << x;
  SDFKIT_EXPECT_NO_VALIDATION_MESSAGES(*ctx);
}

}  // namespace
}  // namespace sdfkit::vk

namespace sdfkit::vk {
namespace {

// A pass may reach only the handles it declared: the buffer of another pass is refused with an
// error naming both, while its own is handed out.
TEST(VulkanRenderGraph, PassContextRefusesAHandleThePassDidNotDeclare) {
  auto ctx = test::make_test_context();
  if (!ctx) GTEST_SKIP() << "no Vulkan device";
  Buffer mine = create_buffer(*ctx, 64, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUse::Readback);
  Buffer other = create_buffer(*ctx, 64, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUse::Readback);
  TransientPool transients(*ctx);
  for (const bool cheat : {false, true}) {
    RenderGraph g;
    auto a = g.import_buffer("mine", 64, {mine.get()});
    auto b = g.import_buffer("other", 64, {other.get()});
    auto fill = g.add_pass("fill", PassKind::Transfer);
    a = fill.transfer_dst(a);
    fill.execute([&, a, b, cheat](PassContext& pc) {
      vkCmdFillBuffer(pc.cmd, pc.buffer(a), 0, VK_WHOLE_SIZE, 7u);
      if (cheat) vkCmdFillBuffer(pc.cmd, pc.buffer(b), 0, VK_WHOLE_SIZE, 7u);
    });
    if (!cheat) {
      EXPECT_NO_THROW(execute(*ctx, g.compile(), transients));
      EXPECT_EQ(static_cast<const std::uint32_t*>(mine.mapped())[0], 7u);
      continue;
    }
    try {
      execute(*ctx, g.compile(), transients);
      ADD_FAILURE() << "an undeclared handle was handed out";
    } catch (const GraphError& e) {
      EXPECT_NE(std::string(e.what()).find("pass 'fill' uses 'other#0', which it did not declare"), std::string::npos)
          << e.what();
    }
  }
  SDFKIT_EXPECT_NO_VALIDATION_MESSAGES(*ctx);
}

}  // namespace
}  // namespace sdfkit::vk

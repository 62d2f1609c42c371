// Atlas dilate pass: the normalized atlas for a texture consumer and the PNG
// (glsl/atlas_dilate.comp). The atlas is first filled with NaN (no chart); then, chart by chart,
// each texel of the rectangle and of `margin` texels around it (half the gutter) takes the
// normalized blurred value of the nearest covered texel of the same chart within `reach`.
#include "atlas_passes.hpp"

#include <bit>
#include <limits>

namespace sdfkit::diffusion::passes {

vk::BufferHandle add_atlas_dilate_pass(vk::RenderGraph& graph, const AtlasDilatePass& in) {
  auto fill = graph.add_pass("atlas.dilate.clear", vk::PassKind::Transfer);
  const vk::BufferHandle cleared = fill.transfer_dst(in.atlas);
  fill.execute([cleared](vk::PassContext& pc) {
    vkCmdFillBuffer(pc.cmd, pc.buffer(cleared), 0, VK_WHOLE_SIZE,
                    std::bit_cast<std::uint32_t>(std::numeric_limits<float>::quiet_NaN()));
  });

  auto p = graph.add_pass("atlas.dilate", vk::PassKind::Compute);
  p.storage_read(in.texels);
  p.storage_read(in.charts);
  const vk::BufferHandle atlas = p.storage_read_write(cleared);
  p.side_effect();  // the host reads the atlas
  p.execute([in, atlas](vk::PassContext& pc) {
    const VkDescriptorSet set =
        pc.descriptor_set(in.pipeline->set_layout.get(), {{0, in.charts}, {1, in.texels}, {2, atlas}});
    vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, in.pipeline->get());
    vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, in.pipeline->layout.get(), 0, 1, &set, 0, nullptr);
    for (std::uint32_t c = 0; c < in.chart_count; ++c) {
      const GpuChart& chart = (*in.charts_host)[c];
      const std::uint32_t w = chart.rect.z + 2 * in.margin, h = chart.rect.w + 2 * in.margin;
      const DilatePush push{c, in.size, in.reach, in.margin};
      vkCmdPushConstants(pc.cmd, in.pipeline->layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
      vkCmdDispatch(pc.cmd, (w + 7) / 8, (h + 7) / 8, 1);
    }
  });
  return atlas;
}

}  // namespace sdfkit::diffusion::passes

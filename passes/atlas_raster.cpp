// Atlas raster pass: the mapping's triangles, one value per corner, into an RG32F atlas
// (value, coverage) cleared to zero (glsl/atlas_raster.*), then copied into the texel buffer the
// blur works on. Fragments outside their triangle's chart rectangle are discarded in the shader.
#include "atlas_passes.hpp"

namespace sdfkit::diffusion::passes {

vk::BufferHandle add_atlas_raster_pass(vk::RenderGraph& graph, const AtlasRasterPass& in) {
  constexpr VkShaderStageFlags kStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  auto raster = graph.add_pass("atlas.raster", vk::PassKind::Graphics);
  const vk::ImageHandle target = raster.color(in.target, vk::LoadOp::Clear, VkClearColorValue{{0.0f, 0.0f, 0.0f, 0.0f}});
  raster.vertex(in.vertices);
  raster.storage_read(in.charts);
  raster.execute([in](vk::PassContext& pc) {
    if (in.vertex_count == 0) return;
    vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, in.pipeline->get());
    const VkDescriptorSet set = pc.descriptor_set(in.pipeline->set_layout.get(), {{0, in.charts}});
    vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, in.pipeline->layout.get(), 0, 1, &set, 0, nullptr);
    const VkBuffer b = pc.buffer(in.vertices);
    const VkDeviceSize offset = 0;
    vkCmdBindVertexBuffers(pc.cmd, 0, 1, &b, &offset);
    const RasterPush push{glm::vec4(2.0f / static_cast<float>(in.size), 0.0f, 0.0f, 0.0f)};
    vkCmdPushConstants(pc.cmd, in.pipeline->layout.get(), kStages, 0, sizeof(push), &push);
    vkCmdDraw(pc.cmd, in.vertex_count, 1, 0, 0);
  });

  auto copy = graph.add_pass("atlas.raster.copy", vk::PassKind::Transfer);
  copy.transfer_src(target);
  const vk::BufferHandle texels = copy.transfer_dst(in.texels);
  copy.execute([target, texels, size = in.size](vk::PassContext& pc) {
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {size, size, 1};
    vkCmdCopyImageToBuffer(pc.cmd, pc.image(target), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pc.buffer(texels), 1,
                           &region);
  });
  return texels;
}

}  // namespace sdfkit::diffusion::passes

// Atlas raster pass: the mapping's triangles, each corner with its mesh vertex's value (read from
// the values buffer by vertex index), into an RG32F atlas (value, coverage) cleared to zero and,
// when the blur is stretch-compensated, an RG32F target of its box half-widths along x and y
// (from the triangle's model units per texel; cleared to -1: none) (glsl/atlas_raster*), then
// copied into the buffers the blur works on. Without a stretch target the pass has one colour
// attachment (the atlas_raster_value.frag pipeline). Fragments outside their triangle's chart
// rectangle are discarded in the shader.
#include "atlas_passes.hpp"

namespace sdfkit::diffusion::passes {

AtlasRasterOutput add_atlas_raster_pass(vk::RenderGraph& graph, const AtlasRasterPass& in) {
  constexpr VkShaderStageFlags kStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  auto raster = graph.add_pass("atlas.raster", vk::PassKind::Graphics);
  const VkClearColorValue zero{{0.0f, 0.0f, 0.0f, 0.0f}};
  const vk::ImageHandle target = raster.color(in.target, vk::LoadOp::Clear, zero);
  const bool with_stretch = in.stretch_target.valid();
  const vk::ImageHandle stretch_target =
      with_stretch ? raster.color(in.stretch_target, vk::LoadOp::Clear, VkClearColorValue{{-1.0f, -1.0f, 0.0f, 0.0f}})
                   : vk::ImageHandle{};
  raster.vertex(in.vertices);
  raster.storage_read(in.vertices);  // the provoking corner reads its triangle's other two there
  raster.storage_read(in.values);
  raster.storage_read(in.charts);
  raster.execute([in](vk::PassContext& pc) {
    if (in.vertex_count == 0) return;
    vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, in.pipeline->get());
    const VkDescriptorSet set = pc.descriptor_set(in.pipeline->set_layout.get(), {{0, in.charts}, {1, in.values}, {2, in.vertices}});
    vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, in.pipeline->layout.get(), 0, 1, &set, 0, nullptr);
    const VkBuffer b = pc.buffer(in.vertices);
    const VkDeviceSize offset = 0;
    vkCmdBindVertexBuffers(pc.cmd, 0, 1, &b, &offset);
    const RasterPush push{glm::vec4(2.0f / static_cast<float>(in.size), 0.0f, 0.0f, 0.0f)};
    vkCmdPushConstants(pc.cmd, in.pipeline->layout.get(), kStages, 0, sizeof(push), &push);
    vkCmdDraw(pc.cmd, in.vertex_count, 1, 0, 0);
  });

  // One copy pass per target (image -> row-major buffer).
  const auto copy_out = [&](const char* name, vk::ImageHandle image, vk::BufferHandle buffer) {
    auto copy = graph.add_pass(name, vk::PassKind::Transfer);
    copy.transfer_src(image);
    const vk::BufferHandle out = copy.transfer_dst(buffer);
    copy.execute([image, out, size = in.size](vk::PassContext& pc) {
      VkBufferImageCopy region{};
      region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      region.imageExtent = {size, size, 1};
      vkCmdCopyImageToBuffer(pc.cmd, pc.image(image), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pc.buffer(out), 1, &region);
    });
    return out;
  };
  AtlasRasterOutput out;
  out.target = target;
  out.stretch_target = stretch_target;
  out.texels = copy_out("atlas.raster.copy", target, in.texels);
  if (with_stretch) out.stretch = copy_out("atlas.raster.stretch_copy", stretch_target, in.stretch);
  return out;
}

}  // namespace sdfkit::diffusion::passes

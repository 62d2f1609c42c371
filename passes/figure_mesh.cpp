// Figure mesh pass: the mesh, coloured by its values through the palette, drawn into each view of
// the figure (glsl/render_mesh.*).
#include "figure_passes.hpp"

namespace sdfkit::render::passes {

void set_view(VkCommandBuffer cmd, const SceneView& v) {
  const VkViewport vp{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.width),
                      static_cast<float>(v.height), 0.0f, 1.0f};
  const VkRect2D sc{{v.x, v.y}, {static_cast<std::uint32_t>(v.width), static_cast<std::uint32_t>(v.height)}};
  vkCmdSetViewport(cmd, 0, 1, &vp);
  vkCmdSetScissor(cmd, 0, 1, &sc);
}

FigureOutput add_figure_mesh_pass(vk::RenderGraph& graph, const FigureMeshPass& in) {
  constexpr VkShaderStageFlags kStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  auto mesh = graph.add_pass("figure.mesh", vk::PassKind::Graphics);
  FigureOutput out;
  out.color = mesh.color(in.color, vk::LoadOp::Clear,
                         VkClearColorValue{{in.background.x, in.background.y, in.background.z, 1.0f}});
  out.depth = mesh.depth(in.depth, vk::LoadOp::Clear, 1.0f);
  mesh.vertex(in.vertices);
  mesh.storage_read(in.palette);
  mesh.execute([in](vk::PassContext& pc) {
    vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, in.pipeline->get());
    const VkDescriptorSet set = pc.descriptor_set(in.pipeline->set_layout.get(), {{0, in.palette}});
    vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, in.pipeline->layout.get(), 0, 1, &set, 0, nullptr);
    const VkBuffer b = pc.buffer(in.vertices);
    const VkDeviceSize offset = 0;
    vkCmdBindVertexBuffers(pc.cmd, 0, 1, &b, &offset);
    for (const SceneView& view : in.views) {
      set_view(pc.cmd, view);
      const MeshPush push{view.view_projection, glm::vec4(view.eye, 0.0f), in.scale};
      vkCmdPushConstants(pc.cmd, in.pipeline->layout.get(), kStages, 0, sizeof(push), &push);
      vkCmdDraw(pc.cmd, in.vertex_count, 1, 0, 0);
    }
  });
  return out;
}

}  // namespace sdfkit::render::passes

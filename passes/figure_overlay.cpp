// Figure overlay pass: segments and square points (a skeleton's edges and nodes, a point cloud's
// sprites) drawn over what is in the colour image in each view (glsl/render_overlay.*), depth
// cleared so they stay on top; the colour is cleared first when nothing was drawn before.
#include "figure_passes.hpp"

namespace sdfkit::render::passes {

FigureOutput add_figure_overlay_pass(vk::RenderGraph& graph, const FigureOverlayPass& in) {
  constexpr VkShaderStageFlags kStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  auto overlay = graph.add_pass("figure.skeleton", vk::PassKind::Graphics);
  FigureOutput out;
  out.color = in.clear_color ? overlay.color(in.color, vk::LoadOp::Clear,
                                            VkClearColorValue{{in.clear_color->x, in.clear_color->y,
                                                               in.clear_color->z, 1.0f}})
                             : overlay.color(in.color, vk::LoadOp::Load);
  out.depth = overlay.depth(in.depth, vk::LoadOp::Clear, 1.0f);  // on top of the mesh
  overlay.storage_read(in.segments);
  overlay.execute([in](vk::PassContext& pc) {
    vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, in.pipeline->get());
    const VkDescriptorSet set = pc.descriptor_set(in.pipeline->set_layout.get(), {{0, in.segments}});
    vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, in.pipeline->layout.get(), 0, 1, &set, 0, nullptr);
    for (const SceneView& view : in.views) {
      set_view(pc.cmd, view);
      const OverlayPush push{view.view_projection,
                             glm::vec4(static_cast<float>(view.width), static_cast<float>(view.height), 0, 0)};
      vkCmdPushConstants(pc.cmd, in.pipeline->layout.get(), kStages, 0, sizeof(push), &push);
      vkCmdDraw(pc.cmd, 6 * in.segment_count, 1, 0, 0);
    }
  });
  return out;
}

}  // namespace sdfkit::render::passes

// Figure sheet pass: a skeleton's sheet triangles filled with one flat colour in each view
// (glsl/figure_sheet.*), over the mesh (depth cleared), depth tested among themselves.
#include "figure_passes.hpp"

namespace sdfkit::render::passes {

FigureOutput add_figure_sheet_pass(vk::RenderGraph& graph, const FigureSheetPass& in) {
  constexpr VkShaderStageFlags kStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  auto sheets = graph.add_pass("figure.sheets", vk::PassKind::Graphics);
  FigureOutput out;
  out.color = sheets.color(in.color, vk::LoadOp::Load);
  out.depth = sheets.depth(in.depth, vk::LoadOp::Clear, 1.0f);  // on top of the mesh
  sheets.storage_read(in.corners);
  sheets.execute([in](vk::PassContext& pc) {
    vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, in.pipeline->get());
    const VkDescriptorSet set = pc.descriptor_set(in.pipeline->set_layout.get(), {{0, in.corners}});
    vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, in.pipeline->layout.get(), 0, 1, &set, 0, nullptr);
    for (const SceneView& view : in.views) {
      set_view(pc.cmd, view);
      const SheetPush push{view.view_projection, in.color_value};
      vkCmdPushConstants(pc.cmd, in.pipeline->layout.get(), kStages, 0, sizeof(push), &push);
      vkCmdDraw(pc.cmd, in.vertex_count, 1, 0, 0);
    }
  });
  return out;
}

}  // namespace sdfkit::render::passes

// Atlas blur passes: a Gaussian as three box filters along x then three along y. One invocation
// walks one row (or column) of one chart with running sums, so the work per texel does not depend
// on the radius; the radii are the chart table's. Fused (glsl/atlas_blur.comp): the three boxes
// of an axis in one dispatch, x from the texel buffer into the scratch buffer, y back. Otherwise
// (glsl/atlas_blur_box.comp, radii beyond the fused shader's rings) one dispatch per box,
// ping-ponging between the two.
#include "atlas_passes.hpp"

#include <string>

namespace sdfkit::diffusion::passes {

vk::BufferHandle add_atlas_blur_passes(vk::RenderGraph& graph, const AtlasBlurPass& in) {
  vk::BufferHandle src = in.texels, dst = in.scratch;  // read from src, write dst, then swap
  const std::uint32_t dispatches = in.fused ? kFusedBlurDispatches : kBoxBlurDispatches;
  const vk::Pipeline* pipeline = in.fused ? in.pipeline : in.box_pipeline;
  for (std::uint32_t step = 0; step < dispatches; ++step) {
    const std::uint32_t axis = in.fused ? step : step / 3, box = in.fused ? 0 : step % 3;
    BlurPush push{};
    push.job_offset = axis == 0 ? 0 : in.row_jobs;
    push.job_count = axis == 0 ? in.row_jobs : in.column_jobs;
    push.size = in.size;
    push.axis = axis;
    push.box = box;
    push.src_tiled = step == 0 ? 0u : 1u;
    auto p = graph.add_pass(std::string("atlas.blur.") + (axis == 0 ? "x" : "y") + (in.fused ? "" : std::to_string(box)),
                            vk::PassKind::Compute);
    p.storage_read(src);
    p.storage_read(in.charts);
    p.storage_read(in.jobs);
    // Only texels inside charts are written, and only those are ever read.
    const vk::BufferHandle out = p.storage_write(dst);
    p.execute([pipeline, src, out, push, charts = in.charts, jobs = in.jobs](vk::PassContext& pc) {
      if (push.job_count == 0) return;
      const VkDescriptorSet set = pc.descriptor_set(pipeline->set_layout.get(),
                                                    {{0, jobs}, {1, charts}, {2, src}, {3, out}});
      vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline->get());
      vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline->layout.get(), 0, 1, &set, 0,
                              nullptr);
      vkCmdPushConstants(pc.cmd, pipeline->layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
      vkCmdDispatch(pc.cmd, (push.job_count + 63) / 64, 1, 1);
    });
    dst = src;  // the next pass writes the buffer this one read (its latest version)
    src = out;
  }
  return src;
}

}  // namespace sdfkit::diffusion::passes

// Atlas blur passes: a Gaussian as three box filters along x then three along y. One invocation
// walks one row (or column) of one chart with running sums, so the work per texel does not depend
// on the radius; the radii are the chart table's. Per axis: one fused dispatch (glsl/atlas_blur.comp,
// the three boxes in one walk) over the lines plan_blur gave it, and three cascade dispatches
// (glsl/atlas_blur_box.comp, one per box) over the others; both end the axis in the same buffer.
// Stretch-compensated (AtlasBlurPass::stretch_pipeline): the cascade's three dispatches per axis
// over every line, each box's width per texel from the raster pass's stretch buffer
// (glsl/atlas_blur_stretch.comp).
#include "atlas_passes.hpp"

#include <string>
#include <utility>

namespace sdfkit::diffusion::passes {

AtlasBlurOutput add_atlas_blur_passes(vk::RenderGraph& graph, const AtlasBlurPass& in) {
  vk::BufferHandle prefix = in.prefix;
  // One dispatch: `count` jobs from `offset`, reading src, writing a new version of dst. `keep`:
  // dst holds another dispatch's charts that are still needed (a partial write, declared as
  // read-write so that the graph neither culls nor reorders that dispatch).
  const auto dispatch = [&](const std::string& name, const vk::Pipeline* pipeline, std::uint32_t axis,
                            std::uint32_t box, bool src_tiled, std::uint32_t offset, std::uint32_t count,
                            vk::BufferHandle src, vk::BufferHandle dst, bool keep) {
    // The stretch shader's push block is BlurPush's with the variance after it.
    StretchBlurPush push{};
    push.job_offset = offset;
    push.job_count = count;
    push.size = in.size;
    push.axis = axis;
    push.box = box;
    push.src_tiled = src_tiled ? 1u : 0u;
    push.variance = in.variance;
    const bool stretched = pipeline == in.stretch_pipeline;
    const std::uint32_t push_bytes = stretched ? sizeof(StretchBlurPush) : sizeof(BlurPush);
    auto p = graph.add_pass(name, vk::PassKind::Compute);
    p.storage_read(src);
    p.storage_read(in.charts);
    p.storage_read(in.jobs);
    // The prefix sums: scratch of every stretched dispatch, which reads only what it wrote there
    // itself (each line's sums before its boxes), so a write: no earlier content is needed.
    vk::BufferHandle prefix_out{};
    if (stretched) {
      p.storage_read(in.stretch);
      prefix_out = p.storage_write(prefix);
      prefix = prefix_out;
    }
    // Only texels inside this dispatch's charts are written.
    const vk::BufferHandle out = keep ? p.storage_read_write(dst) : p.storage_write(dst);
    p.execute([pipeline, src, out, push, push_bytes, stretched, charts = in.charts, jobs = in.jobs,
               stretch = in.stretch, prefix_out](vk::PassContext& pc) {
      const VkDescriptorSet set =
          stretched ? pc.descriptor_set(pipeline->set_layout.get(),
                                        {{0, jobs}, {1, charts}, {2, src}, {3, out}, {4, stretch}, {5, prefix_out}})
                    : pc.descriptor_set(pipeline->set_layout.get(), {{0, jobs}, {1, charts}, {2, src}, {3, out}});
      vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline->get());
      vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline->layout.get(), 0, 1, &set, 0,
                              nullptr);
      vkCmdPushConstants(pc.cmd, pipeline->layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes, &push);
      vkCmdDispatch(pc.cmd, (push.job_count + 63) / 64, 1, 1);
    });
    return out;
  };
  // a: the buffer each axis starts from, b: the one it ends in (x: texels -> scratch, y: back).
  vk::BufferHandle a = in.texels, b = in.scratch;
  const vk::Pipeline* cascade_pipeline = in.stretch_pipeline ? in.stretch_pipeline : in.box_pipeline;
  std::uint32_t offset = 0;
  for (std::uint32_t axis = 0; axis < 2; ++axis) {
    const std::string name = std::string("atlas.blur.") + (axis == 0 ? "x" : "y");
    const std::uint32_t fused = axis == 0 ? in.rows_fused : in.columns_fused;
    const std::uint32_t cascade = axis == 0 ? in.rows_cascade : in.columns_cascade;
    const bool tiled = axis == 1;  // the raster copy the x passes read first is row-major
    if (fused > 0) b = dispatch(name, in.pipeline, axis, 0, tiled, offset, fused, a, b, false);
    offset += fused;
    if (cascade > 0) {
      // Boxes 0 and 2 write into b beside the fused charts' results (kept); box 1 into a, whose
      // other charts are no longer needed. Box 1's write of a waits for the fused dispatch's read
      // of it (write after read).
      const bool keep = fused > 0;
      b = dispatch(name + "0", cascade_pipeline, axis, 0, tiled, offset, cascade, a, b, keep);
      a = dispatch(name + "1", cascade_pipeline, axis, 1, true, offset, cascade, b, a, false);
      b = dispatch(name + "2", cascade_pipeline, axis, 2, true, offset, cascade, a, b, keep);
    }
    offset += cascade;
    std::swap(a, b);  // the next axis reads what this one ended in
  }
  return {a, b, prefix};
}

}  // namespace sdfkit::diffusion::passes

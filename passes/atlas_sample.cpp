// Atlas sample pass: every vertex reads the blurred atlas back at each of its samples, bilinear
// inside the sample's chart (wrapping in x for cylindrical charts), normalized by the blurred
// coverage, and blends the reads by the samples' weights (glsl/atlas_sample.comp).
#include "atlas_passes.hpp"

namespace sdfkit::diffusion::passes {

vk::BufferHandle add_atlas_sample_pass(vk::RenderGraph& graph, const AtlasSamplePass& in) {
  auto p = graph.add_pass("atlas.sample", vk::PassKind::Compute);
  p.storage_read(in.texels);
  p.storage_read(in.charts);
  p.storage_read(in.queries);
  p.storage_read(in.ranges);
  const vk::BufferHandle values = p.storage_read_write(in.values);  // a vertex nothing reaches keeps its value
  p.side_effect();  // the host reads the values
  p.execute([in, values](vk::PassContext& pc) {
    if (in.vertex_count == 0) return;
    const VkDescriptorSet set = pc.descriptor_set(in.pipeline->set_layout.get(),
                                                  {{0, in.charts}, {1, in.texels}, {2, in.queries}, {3, in.ranges}, {4, values}});
    vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, in.pipeline->get());
    vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, in.pipeline->layout.get(), 0, 1, &set, 0, nullptr);
    const SamplePush push{in.vertex_count, in.size};
    vkCmdPushConstants(pc.cmd, in.pipeline->layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
    vkCmdDispatch(pc.cmd, (in.vertex_count + 63) / 64, 1, 1);
  });
  return values;
}

}  // namespace sdfkit::diffusion::passes

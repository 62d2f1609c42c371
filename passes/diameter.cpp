// Diameter pass (Layers mode, the paper's Algorithm 2): per query point and camera of the batch,
// a sample when the point lies between back layers k-1 and k (glsl/diameter.comp).
#include "depth_peel_passes.hpp"

namespace sdfkit::vk::passes {

DiameterOutput add_diameter_pass(RenderGraph& graph, const DiameterPass& in) {
  auto diam = graph.add_pass("diameter", PassKind::Compute);
  diam.sampled(in.previous);
  diam.sampled(in.current);
  diam.storage_read(in.query.cameras);
  diam.storage_read(in.query.points);
  DiameterOutput out;
  out.counts = diam.atomic(in.query.counts);
  out.samples = diam.storage_write(in.query.samples);
  out.pending = diam.atomic(in.pending);
  diam.execute([in, out](PassContext& pc) {
    const VkDescriptorSet set = pc.descriptor_set(in.pipeline->set_layout.get(),
                                                  {{0, in.query.cameras},
                                                   {1, in.query.points},
                                                   {2, out.counts},
                                                   {3, out.samples},
                                                   {4, {}, in.previous, in.sampler},
                                                   {5, {}, in.current, in.sampler},
                                                   {6, out.pending}});
    vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, in.pipeline->get());
    vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, in.pipeline->layout.get(), 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(pc.cmd, in.pipeline->layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(in.push), &in.push);
    vkCmdDispatch(pc.cmd, in.groups, 1, 1);
  });
  return out;
}

}  // namespace sdfkit::vk::passes

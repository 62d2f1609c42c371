// Resolve pass (FragmentLists mode): per query point and camera of the batch, the nearest back
// face behind the point (the exit) and the nearest front face before it; the closest is the hit
// (glsl/fragment_list.comp).
#include "depth_peel_passes.hpp"

namespace sdfkit::vk::passes {

ResolveOutput add_resolve_pass(RenderGraph& graph, const ResolvePass& in) {
  auto rs = graph.add_pass("resolve_lists", PassKind::Compute);
  rs.storage_read(in.heads);
  rs.storage_read(in.nodes);
  rs.storage_read(in.counter);
  rs.storage_read(in.query.cameras);
  rs.storage_read(in.query.points);
  ResolveOutput out;
  out.counts = rs.atomic(in.query.counts);
  out.samples = rs.storage_write(in.query.samples);
  rs.execute([in, out](PassContext& pc) {
    const VkDescriptorSet set = pc.descriptor_set(in.pipeline->set_layout.get(),
                                                  {{0, in.query.cameras},
                                                   {1, in.query.points},
                                                   {2, out.counts},
                                                   {3, out.samples},
                                                   {4, in.heads},
                                                   {5, in.nodes},
                                                   {6, in.counter}});
    vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, in.pipeline->get());
    vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, in.pipeline->layout.get(), 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(pc.cmd, in.pipeline->layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(in.push), &in.push);
    vkCmdDispatch(pc.cmd, in.groups, 1, 1);
  });
  return out;
}

}  // namespace sdfkit::vk::passes

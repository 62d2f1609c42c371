// Peel pass (Layers mode, the paper's Algorithm 1): the next front and back layer of every camera
// of a batch at once (layered rendering, gl_Layer = 2 * camera + back), each fragment kept only
// behind the previous layer of its kind; an occlusion query counts what was drawn.
#include "depth_peel_passes.hpp"

#include "sdfkit/core/sdf_definition_shared.h"

namespace sdfkit::vk::passes {

PeelOutput add_peel_pass(RenderGraph& graph, const PeelPass& in) {
  auto peel = graph.add_pass("peel", PassKind::Graphics);
  peel.sampled(in.previous);
  peel.vertex(in.corners);
  peel.storage_read(in.normals);
  peel.storage_read(in.cameras);
  PeelOutput out;
  out.depth = peel.depth(in.depth, LoadOp::Clear, 1.0f);
  out.target = peel.color(in.target, LoadOp::Clear, VkClearColorValue{.uint32 = {SDFKIT_NO_SURFACE_BITS, 0, 0, 0}});
  peel.queries(in.occlusion);
  peel.execute([in](PassContext& pc) {
    const VkDeviceSize zero = 0;
    const VkBuffer vb = pc.buffer(in.corners);
    vkCmdBindVertexBuffers(pc.cmd, 0, 1, &vb, &zero);
    const VkDescriptorSet set = pc.descriptor_set(
        in.front->set_layout.get(), {{0, in.normals}, {1, in.cameras}, {2, {}, in.previous, in.sampler}});
    vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, in.front->layout.get(), 0, 1, &set, 0, nullptr);
    const VkQueryPool queries = pc.query_pool(in.occlusion);
    vkCmdBeginQuery(pc.cmd, queries, in.query, 0);
    PeelPush push = in.push;
    for (const Pipeline* p : {in.front, in.back}) {
      push.back = p == in.back ? 1u : 0u;
      if (!push.back && !in.front_layers) continue;  // front layers stay empty (no surface)
      vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p->get());
      vkCmdPushConstants(pc.cmd, p->layout.get(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                         sizeof(push), &push);
      vkCmdDraw(pc.cmd, in.corner_count, in.camera_count, 0, 0);
    }
    vkCmdEndQuery(pc.cmd, queries, in.query);
  });
  return out;
}

BufferHandle add_peel_reset_pass(RenderGraph& graph, QueryPoolHandle occlusion, std::uint32_t queries,
                                 BufferHandle pending) {
  auto reset = graph.add_pass("reset_queries", PassKind::Transfer);
  reset.queries(occlusion);
  pending = reset.transfer_dst(pending);
  reset.execute([occlusion, queries, pending](PassContext& pc) {
    vkCmdResetQueryPool(pc.cmd, pc.query_pool(occlusion), 0, queries);
    vkCmdFillBuffer(pc.cmd, pc.buffer(pending), 0, VK_WHOLE_SIZE, 0);
  });
  return pending;
}

}  // namespace sdfkit::vk::passes

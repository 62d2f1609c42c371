// Fragment-list pass (FragmentLists mode): one raster pass per batch of cameras, no depth test,
// every fragment appended to its pixel's list (glsl/fragment_list.*); on closed meshes the
// groups of triangles facing a camera are not drawn at all.
#include "depth_peel_passes.hpp"

#include "sdfkit/core/sdf_definition_shared.h"

#include <glm/geometric.hpp>

namespace sdfkit::vk::passes {

FragmentListOutput add_fragment_list_passes(RenderGraph& graph, const FragmentListPass& in) {
  FragmentListOutput out;
  auto reset = graph.add_pass("reset_lists", PassKind::Transfer);
  out.heads = reset.transfer_dst(in.heads);
  out.counter = reset.transfer_dst(in.counter);
  reset.execute([h = out.heads, c = out.counter](PassContext& pc) {
    vkCmdFillBuffer(pc.cmd, pc.buffer(h), 0, VK_WHOLE_SIZE, SDFKIT_END_OF_LIST);
    vkCmdFillBuffer(pc.cmd, pc.buffer(c), 0, VK_WHOLE_SIZE, 0);
  });

  auto list = graph.add_pass("fragment_lists", PassKind::Graphics);
  list.color(graph.create_image("list_target", in.target_info), LoadOp::DontCare);
  list.vertex(in.corners);
  list.storage_read(in.normals);
  list.storage_read(in.cameras);
  out.heads = list.atomic(out.heads);
  out.counter = list.atomic(out.counter);
  out.nodes = list.storage_write(in.nodes);
  list.execute([in, out](PassContext& pc) {
    const VkDeviceSize zero = 0;
    const VkBuffer vb = pc.buffer(in.corners);
    vkCmdBindVertexBuffers(pc.cmd, 0, 1, &vb, &zero);
    const VkDescriptorSet set =
        pc.descriptor_set(in.pipeline->set_layout.get(),
                          {{0, in.normals}, {1, in.cameras}, {2, out.heads}, {3, out.nodes}, {4, out.counter}});
    vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, in.pipeline->get());
    vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, in.pipeline->layout.get(), 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(pc.cmd, in.pipeline->layout.get(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                       0, sizeof(in.push), &in.push);
    if (in.bins.empty()) {
      vkCmdDraw(pc.cmd, in.corner_count, in.camera_count, 0, 0);
      if (in.submitted) *in.submitted += static_cast<std::size_t>(in.corner_count / 3) * in.camera_count;
      return;
    }
    // One draw per run of consecutive groups that the camera does not skip; the instance
    // index still names the camera within the batch.
    for (std::uint32_t c = 0; c < in.camera_count; ++c) {
      const glm::vec3 view(in.batch_cameras[c].dir);
      for (std::size_t b = 0; b < in.bins.size();) {
        if (glm::dot(in.bins[b].dir, view) < in.bins[b].skip_below) {
          ++b;
          continue;
        }
        const std::uint32_t first = in.bins[b].first;
        std::uint32_t end = first + in.bins[b].count;
        for (++b; b < in.bins.size() && !(glm::dot(in.bins[b].dir, view) < in.bins[b].skip_below); ++b)
          end = in.bins[b].first + in.bins[b].count;
        vkCmdDraw(pc.cmd, 3 * (end - first), 1, 3 * first, c);
        if (in.submitted) *in.submitted += end - first;
      }
    }
  });
  return out;
}

}  // namespace sdfkit::vk::passes

// Gather pass: the shared statistics (sdfkit::gather) per point on its stored samples
// (glsl/gather.comp); also the small transfer passes around it.
#include "depth_peel_passes.hpp"

namespace sdfkit::vk::passes {

BufferHandle add_gather_pass(RenderGraph& graph, const GatherPass& in) {
  auto p = graph.add_pass("gather", PassKind::Compute);
  p.storage_read(in.counts);
  const BufferHandle samples = p.storage_read_write(in.samples);
  const BufferHandle result = p.storage_write(in.result);
  p.execute([in, samples, result](PassContext& pc) {
    const VkDescriptorSet set =
        pc.descriptor_set(in.pipeline->set_layout.get(), {{0, in.counts}, {1, samples}, {2, result}});
    vkCmdBindPipeline(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, in.pipeline->get());
    vkCmdBindDescriptorSets(pc.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, in.pipeline->layout.get(), 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(pc.cmd, in.pipeline->layout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(in.push), &in.push);
    vkCmdDispatch(pc.cmd, in.groups, 1, 1);
  });
  return result;
}

BufferHandle add_clear_counts_pass(RenderGraph& graph, BufferHandle counts) {
  auto clear = graph.add_pass("clear_counts", PassKind::Transfer);
  counts = clear.transfer_dst(counts);
  clear.execute([counts](PassContext& pc) { vkCmdFillBuffer(pc.cmd, pc.buffer(counts), 0, VK_WHOLE_SIZE, 0); });
  return counts;
}

std::vector<BufferHandle> add_copy_pass(RenderGraph& graph, const char* name, std::span<const BufferHandle> src,
                                        std::span<const BufferHandle> dst, std::span<const VkDeviceSize> bytes,
                                        bool host_reads) {
  auto copy = graph.add_pass(name, PassKind::Transfer);
  std::vector<BufferHandle> from(src.begin(), src.end()), to;
  std::vector<VkDeviceSize> size(bytes.begin(), bytes.end());
  for (BufferHandle s : src) copy.transfer_src(s);
  for (BufferHandle d : dst) to.push_back(copy.transfer_dst(d));
  if (host_reads) copy.side_effect();
  copy.execute([from, to, size](PassContext& pc) {
    for (std::size_t i = 0; i < from.size(); ++i) {
      const VkBufferCopy region{0, 0, size[i]};
      vkCmdCopyBuffer(pc.cmd, pc.buffer(from[i]), pc.buffer(to[i]), 1, &region);
    }
  });
  return to;
}

}  // namespace sdfkit::vk::passes

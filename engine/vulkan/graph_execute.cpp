// Executing a compiled render graph: transient resources from the pool, barriers, dynamic
// rendering around graphics passes, optional timestamps.

#include "sdfkit/core/error.hpp"
#include "sdfkit/vulkan/context.hpp"
#include "sdfkit/vulkan/memory.hpp"
#include "sdfkit/vulkan/pipeline.hpp"
#include "sdfkit/vulkan/render_graph.hpp"

#include <algorithm>

namespace sdfkit::vk {

// Descriptor sets for one execution: pools are created as needed and all reset when the next
// execution starts (the previous one has completed: execute() waits for the device).
struct DescriptorAllocator {
  VkDevice device = VK_NULL_HANDLE;
  std::vector<UniqueDescriptorPool> pools;
  std::size_t current = 0;
  void reset() {
    for (auto& p : pools) vkResetDescriptorPool(device, p.get(), 0);
    current = 0;
  }
  VkDescriptorSet allocate(VkDescriptorSetLayout layout) {
    for (;; ++current) {
      if (current == pools.size()) {
        const VkDescriptorPoolSize sizes[] = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1024},
                                              {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 128},
                                              {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 256},
                                              {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 128}};
        VkDescriptorPoolCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO, nullptr, 0, 256,
                                      static_cast<std::uint32_t>(std::size(sizes)), sizes};
        VkDescriptorPool pool = VK_NULL_HANDLE;
        check(vkCreateDescriptorPool(device, &ci, nullptr, &pool), "creating the render graph's descriptor pool");
        pools.emplace_back(device, pool);
      }
      VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO, nullptr, pools[current].get(), 1,
                                     &layout};
      VkDescriptorSet set = VK_NULL_HANDLE;
      const VkResult r = vkAllocateDescriptorSets(device, &ai, &set);
      if (r == VK_SUCCESS) return set;
      if (r != VK_ERROR_OUT_OF_POOL_MEMORY && r != VK_ERROR_FRAGMENTED_POOL)
        check(r, "allocating a descriptor set for a render-graph pass");
    }
  }
};

struct ResolvedResources {
  std::vector<VkImage> images;       // per logical resource
  std::vector<VkImageView> views;
  std::vector<VkBuffer> buffers;
  std::vector<ImageInfo> infos;
  std::vector<std::uint32_t> resource_of_version;
};

bool pass_declares(const CompiledPass& pass, std::uint32_t version) {
  for (const PassUse& u : pass.uses)
    if (u.read_version == version || u.write_version == version) return true;
  return false;
}

std::uint32_t PassContext::declared_resource(std::uint32_t version) const {
  if (!pass_declares(*pass_, version)) {
    const std::string name =
        version < graph_->version_names.size() ? graph_->version_names[version] : std::string("<invalid handle>");
    throw GraphError("pass '" + pass_->name + "' uses '" + name + "', which it did not declare");
  }
  return resolved_->resource_of_version[version];
}

VkImage PassContext::image(ImageHandle h) const { return resolved_->images[declared_resource(h.id)]; }
VkImageView PassContext::view(ImageHandle h) const { return resolved_->views[declared_resource(h.id)]; }
VkBuffer PassContext::buffer(BufferHandle h) const { return resolved_->buffers[declared_resource(h.id)]; }
const ImageInfo& PassContext::image_info(ImageHandle h) const { return resolved_->infos[declared_resource(h.id)]; }

VkQueryPool PassContext::query_pool(QueryPoolHandle h) const {
  if (std::find(pass_->query_pools.begin(), pass_->query_pools.end(), h.id) == pass_->query_pools.end())
    throw GraphError("pass '" + pass_->name + "' uses a query pool it did not declare");
  return graph_->query_pools[h.id];
}

VkDescriptorSet PassContext::descriptor_set(VkDescriptorSetLayout layout, std::initializer_list<Binding> bindings) const {
  std::vector<DescriptorWrite> writes;
  writes.reserve(bindings.size());
  for (const Binding& b : bindings) {
    DescriptorWrite w;
    w.binding = b.binding;
    if (b.buffer.valid()) {
      w.buffer = buffer(b.buffer);
      w.type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      for (const PassUse& u : pass_->uses)
        if (u.read_version == b.buffer.id && u.access == Access::Uniform) w.type = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    } else {
      w.view = view(b.image);
      w.sampler = b.sampler;
      w.type = b.sampler ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER : VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
      w.layout = b.sampler ? VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL : VK_IMAGE_LAYOUT_GENERAL;
    }
    writes.push_back(w);
  }
  const VkDescriptorSet set = descriptors_->allocate(layout);
  write_set(descriptors_->device, set, writes);
  return set;
}

struct TransientPool::Impl {
  explicit Impl(Context& c) : ctx(c) {}
  Context& ctx;
  struct PooledImage {
    ImageInfo info;
    VkImageUsageFlags usage;
    Image image;
  };
  struct PooledBuffer {
    VkDeviceSize size;
    VkBufferUsageFlags usage;
    Buffer buffer;
  };
  std::vector<PooledImage> images;
  std::vector<PooledBuffer> buffers;
  UniqueQueryPool timestamps;
  std::uint32_t timestamp_capacity = 0;
  DescriptorAllocator descriptors;
};

TransientPool::TransientPool(Context& ctx) : impl_(std::make_unique<Impl>(ctx)) {
  impl_->descriptors.device = ctx.device();
}
TransientPool::~TransientPool() = default;
std::size_t TransientPool::image_count() const { return impl_->images.size(); }
std::size_t TransientPool::buffer_count() const { return impl_->buffers.size(); }

class GraphExecutor {
public:
  static std::vector<PassTiming> run(Context& ctx, const CompiledGraph& g, TransientPool& pool,
                                     const ExecuteOptions& options);
};

namespace {

void record_barriers(const Context& ctx, VkCommandBuffer cmd, const std::vector<Barrier>& barriers,
                     const std::vector<VkImage>& images, const std::vector<VkBuffer>& buffers,
                     const std::vector<ImageInfo>& infos) {
  if (barriers.empty()) return;
  std::vector<VkImageMemoryBarrier2> ib;
  std::vector<VkBufferMemoryBarrier2> bb;
  for (const Barrier& b : barriers) {
    if (b.image) {
      VkImageMemoryBarrier2 m{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
      m.srcStageMask = b.src.stages;
      m.srcAccessMask = b.src.access;
      m.dstStageMask = b.dst.stages;
      m.dstAccessMask = b.dst.access;
      m.oldLayout = b.src.layout;
      m.newLayout = b.dst.layout;
      m.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      m.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      m.image = images[b.physical];
      m.subresourceRange = {aspect_of(infos[b.physical].format), 0, 1, 0, infos[b.physical].layers};
      ib.push_back(m);
    } else {
      VkBufferMemoryBarrier2 m{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
      m.srcStageMask = b.src.stages;
      m.srcAccessMask = b.src.access;
      m.dstStageMask = b.dst.stages;
      m.dstAccessMask = b.dst.access;
      m.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      m.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      m.buffer = buffers[b.physical];
      m.offset = 0;
      m.size = VK_WHOLE_SIZE;
      bb.push_back(m);
    }
  }
  VkDependencyInfo di{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  di.imageMemoryBarrierCount = static_cast<std::uint32_t>(ib.size());
  di.pImageMemoryBarriers = ib.data();
  di.bufferMemoryBarrierCount = static_cast<std::uint32_t>(bb.size());
  di.pBufferMemoryBarriers = bb.data();
  ctx.functions().cmd_pipeline_barrier2(cmd, &di);
}

}  // namespace

std::vector<PassTiming> GraphExecutor::run(Context& ctx, const CompiledGraph& g, TransientPool& pool,
                                           const ExecuteOptions& options) {
  TransientPool::Impl& tp = *pool.impl_;
  const std::size_t nphys = g.physical.size();
  std::vector<VkImage> p_images(nphys, VK_NULL_HANDLE);
  std::vector<VkImageView> p_views(nphys, VK_NULL_HANDLE);
  std::vector<VkBuffer> p_buffers(nphys, VK_NULL_HANDLE);
  std::vector<ImageInfo> p_infos(nphys);
  std::vector<char> image_taken(tp.images.size(), 0), buffer_taken(tp.buffers.size(), 0);

  for (std::size_t s = 0; s < nphys; ++s) {
    const PhysicalResource& ph = g.physical[s];
    p_infos[s] = ph.info;
    if (ph.imported) {
      p_images[s] = ph.external_image;
      p_views[s] = ph.external_view;
      p_buffers[s] = ph.external_buffer;
      continue;
    }
    if (ph.image) {
      std::size_t k = 0;
      for (; k < tp.images.size(); ++k)
        if (!image_taken[k] && tp.images[k].info == ph.info && (tp.images[k].usage & ph.usage) == ph.usage) break;
      if (k == tp.images.size()) {
        ImageDescription d{ph.info.format, ph.info.width, ph.info.height, ph.info.layers, ph.usage};
        tp.images.push_back({ph.info, ph.usage, create_image(ctx, d)});
        image_taken.push_back(0);
      }
      image_taken[k] = 1;
      p_images[s] = tp.images[k].image.get();
      p_views[s] = tp.images[k].image.view.get();
    } else {
      std::size_t k = 0;
      for (; k < tp.buffers.size(); ++k)
        if (!buffer_taken[k] && tp.buffers[k].size == ph.size && (tp.buffers[k].usage & ph.usage) == ph.usage) break;
      if (k == tp.buffers.size()) {
        tp.buffers.push_back({ph.size, ph.usage, create_buffer(ctx, ph.size, ph.usage, MemoryUse::DeviceLocal)});
        buffer_taken.push_back(0);
      }
      buffer_taken[k] = 1;
      p_buffers[s] = tp.buffers[k].buffer.get();
    }
  }

  ResolvedResources resolved;
  const std::size_t nres = g.physical_of.size();
  resolved.images.resize(nres, VK_NULL_HANDLE);
  resolved.views.resize(nres, VK_NULL_HANDLE);
  resolved.buffers.resize(nres, VK_NULL_HANDLE);
  resolved.infos.resize(nres);
  for (std::size_t r = 0; r < nres; ++r) {
    const std::uint32_t s = g.physical_of[r];
    if (s == UINT32_MAX) continue;
    resolved.images[r] = p_images[s];
    resolved.views[r] = p_views[s];
    resolved.buffers[r] = p_buffers[s];
    resolved.infos[r] = p_infos[s];
  }
  // Version id -> logical resource, from the names ("name#v") is fragile; use the uses instead.
  resolved.resource_of_version.assign(g.version_names.size(), 0);
  for (const CompiledPass& p : g.passes)
    for (const PassUse& u : p.uses) {
      resolved.resource_of_version[u.read_version] = u.resource;
      if (u.write_version != UINT32_MAX) resolved.resource_of_version[u.write_version] = u.resource;
    }

  const bool profile = options.profile && ctx.capabilities().timestamps;
  const auto nq = static_cast<std::uint32_t>(2 * g.passes.size());
  if (profile && tp.timestamp_capacity < nq) {
    VkQueryPoolCreateInfo qi{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO, nullptr, 0, VK_QUERY_TYPE_TIMESTAMP,
                             std::max<std::uint32_t>(nq, 64), 0};
    VkQueryPool qp = VK_NULL_HANDLE;
    check(vkCreateQueryPool(ctx.device(), &qi, nullptr, &qp), "creating a timestamp query pool");
    tp.timestamps = UniqueQueryPool(ctx.device(), qp);
    tp.timestamp_capacity = qi.queryCount;
  }
  const VkQueryPool qpool = tp.timestamps.get();
  tp.descriptors.reset();

  ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    if (profile) vkCmdResetQueryPool(cmd, qpool, 0, nq);
    for (std::size_t i = 0; i < g.passes.size(); ++i) {
      const CompiledPass& p = g.passes[i];
      record_barriers(ctx, cmd, p.barriers, p_images, p_buffers, p_infos);
      if (profile)
        ctx.functions().cmd_write_timestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, qpool,
                                             static_cast<std::uint32_t>(2 * i));
      const bool graphics = p.kind == PassKind::Graphics;
      if (graphics) {
        std::vector<VkRenderingAttachmentInfo> colors;
        VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        bool has_depth = false;
        ImageInfo area{};
        for (const PassUse& u : p.uses) {
          if (u.access != Access::ColorAttachment && u.access != Access::DepthAttachment &&
              u.access != Access::DepthReadOnly)
            continue;
          VkRenderingAttachmentInfo a{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
          a.imageView = resolved.views[u.resource];
          a.imageLayout = access_state(u.access, p.kind, true).layout;
          a.loadOp = u.load == LoadOp::Clear  ? VK_ATTACHMENT_LOAD_OP_CLEAR
                     : u.load == LoadOp::Load ? VK_ATTACHMENT_LOAD_OP_LOAD
                                              : VK_ATTACHMENT_LOAD_OP_DONT_CARE;
          a.storeOp = u.access == Access::DepthReadOnly ? VK_ATTACHMENT_STORE_OP_NONE : VK_ATTACHMENT_STORE_OP_STORE;
          a.clearValue = u.clear;
          if (area.width <= 1 && area.height <= 1) area = resolved.infos[u.resource];
          else area.layers = std::min(area.layers, resolved.infos[u.resource].layers);
          if (u.access == Access::ColorAttachment) colors.push_back(a);
          else {
            depth = a;
            has_depth = true;
          }
        }
        VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
        ri.renderArea = {{0, 0}, {area.width, area.height}};
        ri.layerCount = area.layers;
        ri.colorAttachmentCount = static_cast<std::uint32_t>(colors.size());
        ri.pColorAttachments = colors.data();
        ri.pDepthAttachment = has_depth ? &depth : nullptr;
        ctx.functions().cmd_begin_rendering(cmd, &ri);
        VkViewport vp{0.0f, 0.0f, static_cast<float>(area.width), static_cast<float>(area.height), 0.0f, 1.0f};
        VkRect2D sc{{0, 0}, {area.width, area.height}};
        vkCmdSetViewport(cmd, 0, 1, &vp);
        vkCmdSetScissor(cmd, 0, 1, &sc);
      }
      if (p.fn) {
        PassContext pc;
        pc.cmd = cmd;
        pc.resolved_ = &resolved;
        pc.graph_ = &g;
        pc.pass_ = &p;
        pc.descriptors_ = &tp.descriptors;
        p.fn(pc);
      }
      if (graphics) ctx.functions().cmd_end_rendering(cmd);
      if (profile)
        ctx.functions().cmd_write_timestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, qpool,
                                             static_cast<std::uint32_t>(2 * i + 1));
    }
    record_barriers(ctx, cmd, g.final_barriers, p_images, p_buffers, p_infos);
    // The host reads mapped buffers after the fence (read-backs, counters): make every device
    // write of the graph available and visible to host reads.
    VkMemoryBarrier2 to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
    to_host.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    to_host.srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT;
    to_host.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
    to_host.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
    VkDependencyInfo host_dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    host_dep.memoryBarrierCount = 1;
    host_dep.pMemoryBarriers = &to_host;
    ctx.functions().cmd_pipeline_barrier2(cmd, &host_dep);
  });

  for (const auto& [history, layout] : g.history_layouts) history->layout = layout;

  std::vector<PassTiming> timings;
  if (profile && nq > 0) {
    std::vector<std::uint64_t> ticks(nq);
    check(vkGetQueryPoolResults(ctx.device(), qpool, 0, nq, nq * sizeof(std::uint64_t), ticks.data(),
                                sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "reading timestamps");
    for (std::size_t i = 0; i < g.passes.size(); ++i)
      timings.push_back({g.passes[i].name, static_cast<double>(ticks[2 * i + 1] - ticks[2 * i]) *
                                               ctx.capabilities().timestamp_period_ns * 1e-6});
  }
  return timings;
}

std::vector<PassTiming> execute(Context& ctx, const CompiledGraph& graph, TransientPool& pool,
                                const ExecuteOptions& options) {
  return GraphExecutor::run(ctx, graph, pool, options);
}

}  // namespace sdfkit::vk

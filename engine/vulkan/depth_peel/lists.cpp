// FragmentLists mode: per batch of cameras one render graph of the fragment-list and resolve
// passes (passes/fragment_list.cpp, passes/resolve.cpp); a batch whose fragments overflowed
// the node buffer is run again after growing it.
#include "session.hpp"

#include "sdfkit/core/log.hpp"

#include <algorithm>

namespace sdfkit::vk {

void DepthPeelBackend::Impl::run_lists(std::size_t n, std::uint32_t max_samples, float cos_half, FalseHitRule rule,
                                       std::vector<PassTiming>& gpu) {
  const auto res = static_cast<std::uint32_t>(cfg.resolution);
  const auto corner_count = static_cast<std::uint32_t>(3 * drawn.size());
  const auto groups = static_cast<std::uint32_t>((n + 63) / 64);
  const Pipeline& raster = front_layers ? list_all : list_back;
  dropped = 0;
  submitted = 0;
  const int first_camera = camera_begin, end_camera = camera_end > 0 ? camera_end : cfg.views;
  for (int base = first_camera; base < end_camera;) {
    const auto count = static_cast<std::uint32_t>(std::min(batch, end_camera - base));
    RenderGraph g;
    passes::QueryBuffers q = import_query(g);
    const BufferHandle corners = g.import_buffer("corners", corner_buffer.size, {corner_buffer.get()});
    const BufferHandle normals = g.import_buffer("normals", normal_buffer.size, {normal_buffer.get()});
    if (base == first_camera) q.counts = passes::add_clear_counts_pass(g, q.counts);

    passes::FragmentListPass lp;
    lp.pipeline = &raster;
    lp.corners = corners;
    lp.normals = normals;
    lp.cameras = q.cameras;
    lp.heads = g.import_buffer("list_heads", heads.size, {heads.get()});
    lp.nodes = g.import_buffer("list_nodes", nodes.size, {nodes.get()});
    lp.counter = g.import_buffer("list_counter", counter.size, {counter.get()});
    lp.target_info = {kListTargetFormat, res, res, 1};
    lp.bins = bins;
    lp.batch_cameras = std::span<const GpuCamera>(cameras).subspan(static_cast<std::size_t>(base), count);
    lp.corner_count = corner_count;
    lp.camera_count = count;
    lp.submitted = &submitted;
    lp.push = {center_scale(), static_cast<std::uint32_t>(base), cfg.resolution,
               static_cast<std::uint32_t>(node_capacity)};
    const passes::FragmentListOutput lists_out = passes::add_fragment_list_passes(g, lp);

    passes::ResolvePass rp;
    rp.pipeline = &resolve;
    rp.query = q;
    rp.heads = lists_out.heads;
    rp.nodes = lists_out.nodes;
    rp.counter = lists_out.counter;
    rp.groups = groups;
    rp.push = {center_scale(), static_cast<std::uint32_t>(base), count, static_cast<std::uint32_t>(n),
               max_samples, cos_half, static_cast<std::uint32_t>(rule), cfg.resolution,
               1.0f / static_cast<float>(cfg.resolution), static_cast<std::uint32_t>(node_capacity)};
    passes::add_resolve_pass(g, rp);

    const CompiledGraph plan = g.compile();
    if (base == first_camera && log_level() <= LogLevel::Debug)
      log_debug("fragment-list render graph (first batch):\n" + plan.describe());
    auto t = execute(*ctx, plan, transients, {.profile = cfg.profile});
    gpu.insert(gpu.end(), t.begin(), t.end());

    const std::uint32_t appended = *static_cast<const std::uint32_t*>(counter.mapped());
    if (appended > node_capacity) {
      // The resolve pass skipped this batch: grow and run it again.
      dropped += appended - node_capacity;
      grow_nodes(static_cast<std::size_t>(appended) + appended / 4);
      continue;
    }
    base += static_cast<int>(count);
  }
}

}  // namespace sdfkit::vk

// Layers mode (the paper's Algorithms 1 and 2): per batch of cameras, submissions of a few peel
// steps, each a peel pass (passes/peel.cpp) and a diameter pass (passes/diameter.cpp) over the
// ring of three layer images, which the render graph keeps from one submission to the next. A
// camera stops when its last layer was empty or no point can still be reached.
#include "session.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"

#include <algorithm>
#include <string>

namespace sdfkit::vk {

bool DepthPeelBackend::Impl::run_layers(std::size_t n, std::uint32_t max_samples, float cos_half, FalseHitRule rule,
                                        std::vector<PassTiming>& gpu) {
  const auto res = static_cast<std::uint32_t>(cfg.resolution);
  const ImageInfo ring_info{kLayerFormat, res, res, static_cast<std::uint32_t>(2 * batch)};
  const ImageInfo depth_info{kDepthFormat, res, res, static_cast<std::uint32_t>(2 * batch)};
  const auto corner_count = static_cast<std::uint32_t>(3 * drawn.size());
  const auto groups = static_cast<std::uint32_t>((n + 63) / 64);
  bool cap_hit = false;
  int previous_camera_layers = 1;
  for (int base = 0; base < cfg.views; base += batch) {
    const auto count = static_cast<std::uint32_t>(std::min(batch, cfg.views - base));
    int layer = 1;
    bool more = true;
    while (more && layer <= cfg.max_layers) {
      const int wanted = layers_per_submit > 0 ? layers_per_submit
                         : layer == 1         ? std::max(1, previous_camera_layers - 1)
                                              : 1;
      const int steps = std::min(wanted, cfg.max_layers - layer + 1);
      RenderGraph g;
      ImageHandle rings[3];
      for (int r = 0; r < 3; ++r) rings[r] = g.import_history("layer" + std::to_string(r), ring_info, ring_history[r]);
      ImageHandle depth = g.create_image("depth", depth_info);
      passes::QueryBuffers q = import_query(g);
      const BufferHandle corners = g.import_buffer("corners", corner_buffer.size, {corner_buffer.get()});
      const BufferHandle normals = g.import_buffer("normals", normal_buffer.size, {normal_buffer.get()});
      const QueryPoolHandle queries = g.import_query_pool("occlusion", occlusion.get());
      if (base == 0 && layer == 1) q.counts = passes::add_clear_counts_pass(g, q.counts);
      BufferHandle pend = g.import_buffer("pending", pending.size, {pending.get()});
      pend = passes::add_peel_reset_pass(g, queries, static_cast<std::uint32_t>(steps), pend);
      for (int s = 0; s < steps; ++s) {
        const int k = layer + s;
        const int cur = k % 3, prev = (k + 2) % 3;
        const auto first = static_cast<std::uint32_t>(k == 1);
        passes::PeelPass pp;
        pp.front = &peel_front;
        pp.back = &peel_back;
        pp.front_layers = front_layers;
        pp.sampler = sampler.get();
        pp.corners = corners;
        pp.normals = normals;
        pp.cameras = q.cameras;
        pp.previous = rings[prev];
        pp.target = rings[cur];
        pp.depth = depth;
        pp.occlusion = queries;
        pp.query = static_cast<std::uint32_t>(s);
        pp.corner_count = corner_count;
        pp.camera_count = count;
        pp.push = {center_scale(), static_cast<std::uint32_t>(base), first, kPeelEpsilon, 0};
        const passes::PeelOutput peeled = passes::add_peel_pass(g, pp);
        rings[cur] = peeled.target;
        depth = peeled.depth;

        passes::DiameterPass dp;
        dp.pipeline = &diameter;
        dp.sampler = sampler.get();
        dp.query = q;
        dp.previous = rings[prev];
        dp.current = rings[cur];
        dp.pending = pend;
        dp.groups = groups;
        dp.push = {center_scale(), static_cast<std::uint32_t>(base), count, first, static_cast<std::uint32_t>(n),
                   max_samples, cos_half, static_cast<std::uint32_t>(rule), cfg.resolution,
                   1.0f / static_cast<float>(cfg.resolution), static_cast<std::uint32_t>(s)};
        const passes::DiameterOutput measured = passes::add_diameter_pass(g, dp);
        q.counts = measured.counts;
        q.samples = measured.samples;
        pend = measured.pending;
      }
      const CompiledGraph plan = g.compile();
      if (base == 0 && layer == 1 && log_level() <= LogLevel::Debug)
        log_debug("depth peel render graph (first submission):\n" + plan.describe());
      auto t = execute(*ctx, plan, transients, {.profile = cfg.profile});
      gpu.insert(gpu.end(), t.begin(), t.end());

      std::vector<std::uint64_t> frags(static_cast<std::size_t>(steps));
      check(vkGetQueryPoolResults(ctx->device(), occlusion.get(), 0, static_cast<std::uint32_t>(steps),
                                  frags.size() * 8, frags.data(), 8, VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
            "reading occlusion queries");
      // Stop after the first step whose layer was empty, or after which no query point can
      // still be accepted (every candidate lies in front of that back layer).
      const auto* pending_points = static_cast<const std::uint32_t*>(pending.mapped());
      for (int s = 0; s < steps; ++s)
        if (frags[static_cast<std::size_t>(s)] == 0 || pending_points[s] == 0) {
          more = false;
          const int used = frags[static_cast<std::size_t>(s)] == 0 ? layer + s - 1 : layer + s;
          last_layers = std::max(last_layers, used);
          previous_camera_layers = layer + s;  // passes this camera needed
          break;
        }
      layer += steps;
      if (more && layer > cfg.max_layers) {
        cap_hit = true;
        last_layers = cfg.max_layers;
      }
    }
  }
  return cap_hit;
}

}  // namespace sdfkit::vk

// Chunking: a query whose per-point sample storage exceeds one storage buffer runs in chunks of
// points, each rasterizing every camera again; the stage timings add up.
#include "session.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

namespace sdfkit::vk {

double estimated_cpu_seconds(std::size_t triangles, int views, std::size_t chunks, int lanes) {
  constexpr double kSecondsPerTriangleDraw = 0.3e-6;
  return kSecondsPerTriangleDraw * static_cast<double>(triangles) * static_cast<double>(std::max(views, 1)) *
         static_cast<double>(std::max<std::size_t>(chunks, 1)) / static_cast<double>(std::max(lanes, 1));
}

void DepthPeelBackend::warn_if_slow(std::size_t points, std::size_t per_chunk) const {
  const Impl& m = *impl_;
  if (m.ctx->info().type != "cpu" || !(m.cfg.warn_after_seconds > 0.0) || per_chunk == 0) return;
  const std::size_t chunks = (points + per_chunk - 1) / per_chunk;
  const double seconds = estimated_cpu_seconds(m.triangles.size(), m.cfg.views, chunks, lanes());
  if (seconds <= m.cfg.warn_after_seconds) return;
  char line[320];
  std::snprintf(line, sizeof line,
                "depth peeling %zu triangles x %d views in %zu chunk(s) on the CPU device %s will take about %.0f s or "
                "more (0.3 us per triangle and view on a CPU rasterizer); --backend opencl is far faster on CPUs",
                m.triangles.size(), m.cfg.views, chunks, m.ctx->info().name.c_str(), seconds);
  log_warning(line);
}

RawSdf DepthPeelBackend::compute_in_chunks(const SdfQuery& query, const SdfOptions& options, std::size_t per_chunk) {
  in_chunks_ = true;  // the chunks' compute calls warn no more
  struct Reset {
    bool& flag;
    ~Reset() { flag = false; }
  } reset{in_chunks_};
  RawSdf out;
  out.values.reserve(query.size());
  out.kept_rays.reserve(query.size());
  std::vector<StageTiming> total;
  std::size_t chunks = 0;
  for (std::size_t begin = 0; begin < query.size(); begin += per_chunk, ++chunks) {
    const std::size_t end = std::min(query.size(), begin + per_chunk);
    SdfQuery part;
    part.domain = query.domain;
    part.origin_offset = query.origin_offset;
    part.origins = query.origins.subspan(begin, end - begin);  // a view of the caller's points
    part.normals.assign(query.normals.begin() + static_cast<std::ptrdiff_t>(begin), query.normals.begin() + static_cast<std::ptrdiff_t>(end));
    if (!query.valid.empty())
      part.valid.assign(query.valid.begin() + static_cast<std::ptrdiff_t>(begin), query.valid.begin() + static_cast<std::ptrdiff_t>(end));
    RawSdf r = compute(part, options);
    out.values.insert(out.values.end(), r.values.begin(), r.values.end());
    out.kept_rays.insert(out.kept_rays.end(), r.kept_rays.begin(), r.kept_rays.end());
    for (const StageTiming& t : impl_->timings) {
      auto it = std::find_if(total.begin(), total.end(), [&](const StageTiming& x) { return x.stage == t.stage; });
      if (it == total.end())
        total.push_back(t);
      else if (t.stage != "upload_mesh")
        it->milliseconds += t.milliseconds;
    }
  }
  log_info("depth peeling: " + std::to_string(query.size()) + " points in " + std::to_string(chunks) +
           " chunks (the per-point sample storage exceeds one storage buffer)");
  impl_->timings = std::move(total);
  return out;
}

}  // namespace sdfkit::vk

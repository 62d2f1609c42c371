// DepthPeelBackend: the session's public face (see depth_peel.hpp for the method): mesh upload
// into every lane, compute() choosing chunks, lanes and the peel mode, then the gather.
#include "session.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"
#include "sdfkit/core/topology.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <future>
#include <map>
#include <string>

namespace sdfkit::vk {

DepthPeelBackend::DepthPeelBackend(const DepthPeelConfig& config) : impl_(std::make_unique<Impl>(config)) {
  if (resolve_lanes(config, *impl_->ctx) == 2) {
    lane_ = std::make_unique<Impl>(config);
    const int half = config.views / 2;
    impl_->camera_end = half;
    lane_->camera_begin = half;
    lane_->camera_end = config.views;
  }
}
DepthPeelBackend::~DepthPeelBackend() = default;

std::string DepthPeelBackend::device_name() const { return impl_->ctx->info().name; }
Context& DepthPeelBackend::context() { return *impl_->ctx; }
const DepthPeelConfig& DepthPeelBackend::config() const { return impl_->cfg; }
int DepthPeelBackend::last_layer_count() const { return impl_->last_layers; }
std::size_t DepthPeelBackend::fragment_capacity() const { return impl_->node_capacity; }
std::size_t DepthPeelBackend::last_dropped_fragments() const {
  return impl_->dropped + (lane_ ? lane_->dropped : 0);
}
std::size_t DepthPeelBackend::last_submitted_triangles() const {
  return impl_->submitted + (lane_ ? lane_->submitted : 0);
}
int DepthPeelBackend::lanes() const { return lane_ ? 2 : 1; }
bool DepthPeelBackend::peels_front_layers() const { return impl_->front_layers; }
std::vector<StageTiming> DepthPeelBackend::last_timings() const { return impl_->timings; }
std::size_t DepthPeelBackend::device_memory_bytes() const {
  return static_cast<std::size_t>(impl_->ctx->allocator().peak_bytes_in_use()) +
         (lane_ ? static_cast<std::size_t>(lane_->ctx->allocator().peak_bytes_in_use()) : 0);
}

void DepthPeelBackend::set_mesh(const Mesh& mesh) {
  const auto t0 = Clock::now();
  validate_mesh(mesh, "the mesh given to the Vulkan backend");
  const MeshReport report = analyze(mesh);
  const bool front_layers = impl_->cfg.front_layers == FrontLayers::Always || report.boundary_edges > 0 ||
                            report.non_manifold_edges > 0;
  for (Impl* lane : {impl_.get(), lane_.get()}) {
    if (!lane) continue;
    lane->triangles = mesh.triangles;
    lane->vertex_count = mesh.positions.size();
    lane->front_layers = front_layers;
  }
  const Impl::DrawGeometry geometry = impl_->prepare_geometry(mesh.positions);
  for (Impl* lane : {impl_.get(), lane_.get()}) {
    if (!lane) continue;
    lane->upload_geometry(geometry);
  }
  impl_->timings = {{"upload_mesh", ms_since(t0)}};
}

void DepthPeelBackend::update_positions(std::span<const glm::vec3> positions) {
  if (impl_->triangles.empty()) throw Error("update_positions() called before set_mesh()");
  if (positions.size() != impl_->vertex_count)
    throw Error("update_positions() got " + std::to_string(positions.size()) + " positions for a mesh of " +
                std::to_string(impl_->vertex_count) + " vertices");
  const auto t0 = Clock::now();
  const Impl::DrawGeometry geometry = impl_->prepare_geometry(positions);
  impl_->upload_geometry(geometry);
  if (lane_) lane_->upload_geometry(geometry);
  impl_->timings = {{"upload_mesh", ms_since(t0)}};
}

RawSdf DepthPeelBackend::compute(const SdfQuery& query, const SdfOptions& options) {
  Impl& m = *impl_;
  validate_options(options);
  if (m.triangles.empty()) throw Error("compute() called before set_mesh()");
  // Keep the geometry upload of the preceding set_mesh/update_positions, replace the rest.
  std::erase_if(m.timings, [](const StageTiming& t) { return t.stage != "upload_mesh"; });
  m.ctx->allocator().reset_peak();
  if (lane_) lane_->ctx->allocator().reset_peak();
  const std::size_t n = query.size();
  if (n == 0) return {};

  auto t0 = Clock::now();
  const std::uint32_t max_samples = m.cfg.max_samples_per_point > 0
                                        ? static_cast<std::uint32_t>(m.cfg.max_samples_per_point)
                                        : m.auto_max_samples(options.cone_degrees);
  // The per-point sample storage must fit one storage buffer: larger queries run in chunks of
  // points, each chunk rasterizing every camera again (a huge mesh costs more passes, not more
  // memory than the device can address).
  const std::size_t per_chunk = static_cast<std::size_t>(
      m.ctx->capabilities().max_storage_buffer_range / (static_cast<VkDeviceSize>(max_samples) * sizeof(glm::vec2)));
  const std::size_t limit = m.cfg.max_points_per_chunk > 0
                                ? std::min(per_chunk, static_cast<std::size_t>(m.cfg.max_points_per_chunk))
                                : per_chunk;
  if (limit == 0)
    throw DeviceError("one point's sample storage exceeds the device's storage buffer range; use fewer views or a "
                      "smaller max_samples_per_point");
  if (!in_chunks_) warn_if_slow(n, limit);
  if (n > limit) return compute_in_chunks(query, options, limit);
  m.ensure_query_buffers(n, max_samples);
  m.upload_points(query);
  Impl* lane = m.lists ? lane_.get() : nullptr;
  if (lane) {
    lane->ensure_query_buffers(n, max_samples);
    lane->upload_points(query);
  }
  m.timings.push_back({"upload", ms_since(t0)});

  t0 = Clock::now();
  const float cos_half = cos_half_cone(options.cone_degrees);
  std::vector<PassTiming> gpu;
  bool cap_hit = false;
  m.last_layers = 0;
  if (m.lists) {
    if (lane) {
      // Two lanes: each context renders its half of the cameras on its own thread (lavapipe
      // bins on one thread per queue, so the second context's binning overlaps the first one's
      // rasterization), then the second lane's samples are appended to the first lane's per point.
      std::vector<PassTiming> lane_gpu;
      auto other = std::async(std::launch::async, [&] {
        lane->run_lists(n, max_samples, cos_half, options.false_hit, lane_gpu);
        lane->stage_samples(n, max_samples, lane_gpu);
      });
      std::exception_ptr failure;
      try {
        m.run_lists(n, max_samples, cos_half, options.false_hit, gpu);
        m.stage_samples(n, max_samples, gpu);
      } catch (...) {
        failure = std::current_exception();
      }
      other.get();  // rethrows the lane's failure
      if (failure) std::rethrow_exception(failure);
      gpu.insert(gpu.end(), lane_gpu.begin(), lane_gpu.end());
      for (const std::string& message : lane->ctx->validation_messages())
        m.ctx->report_validation_message(VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
                                         ("(second lane) " + message).c_str());
      lane->ctx->clear_validation_messages();
      m.append_lane_samples(*lane, n, max_samples);
    } else {
      m.run_lists(n, max_samples, cos_half, options.false_hit, gpu);
    }
    m.last_layers = 1;
    const std::size_t dropped = m.dropped + (lane ? lane->dropped : 0);
    const std::size_t capacity = std::max(m.node_capacity, lane ? lane->node_capacity : 0);
    if (dropped > 0)
      log_warning("the fragment-list node buffer overflowed (" + std::to_string(dropped) +
                  " fragments dropped); it was grown to " + std::to_string(capacity) +
                  " nodes and the affected camera batches were run again");
  }

  if (!m.lists) cap_hit = m.run_layers(n, max_samples, cos_half, options.false_hit, gpu);
  if (cap_hit)
    log_warning("depth peeling stopped at max_layers = " + std::to_string(m.cfg.max_layers) +
                " with fragments still coming; deeper layers were ignored");
  m.timings.push_back({m.lists ? "lists_and_resolve" : "peel_and_diameter", ms_since(t0)});

  t0 = Clock::now();
  RawSdf out = m.lists && lane ? m.run_gather(n, max_samples, &gpu, &m.staged_counts, &m.staged_samples)
                               : m.run_gather(n, max_samples, &gpu);
  m.timings.push_back({"gather", ms_since(t0)});

  const auto* accepted = static_cast<const std::uint32_t*>(m.result.mapped());
  std::size_t overflow = 0;
  for (std::size_t i = 0; i < n; ++i) overflow += accepted[4 * i + 2] > max_samples;
  if (overflow > 0)
    log_warning(std::to_string(overflow) + " points had more than " + std::to_string(max_samples) +
                " accepted views; the extra samples were dropped");

  if (m.cfg.profile) {
    std::map<std::string, double> sums;
    for (const auto& p : gpu) sums[p.pass] += p.gpu_milliseconds;
    for (const auto& [name, msec] : sums) m.timings.push_back({"gpu_" + name, msec, true});
  }
  return out;
}

RawSdf DepthPeelBackend::gather_on_device(const std::vector<std::vector<std::pair<float, float>>>& samples) {
  Impl& m = *impl_;
  const std::size_t n = samples.size();
  std::uint32_t max_samples = 1;
  for (const auto& s : samples) max_samples = std::max<std::uint32_t>(max_samples, static_cast<std::uint32_t>(s.size()));
  m.ensure_query_buffers(n, max_samples);
  Buffer staged_counts = create_buffer(*m.ctx, m.counts.size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUse::Upload);
  Buffer staged_samples = create_buffer(*m.ctx, m.samples.size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUse::Upload);
  std::memset(staged_counts.mapped(), 0, m.counts.size);
  auto* cnt = static_cast<std::uint32_t*>(staged_counts.mapped());
  auto* smp = static_cast<glm::vec2*>(staged_samples.mapped());
  for (std::size_t i = 0; i < n; ++i) {
    cnt[i] = static_cast<std::uint32_t>(samples[i].size());
    for (std::size_t j = 0; j < samples[i].size(); ++j)
      smp[i * max_samples + j] = glm::vec2(samples[i][j].first, samples[i][j].second);
  }
  return m.run_gather(n, max_samples, nullptr, &staged_counts, &staged_samples);
}

}  // namespace sdfkit::vk

#include "vulkan_bench.hpp"

#include <algorithm>
#include <chrono>

namespace sdfkit::bench {

namespace {
using Clock = std::chrono::steady_clock;
double ms(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}
}  // namespace

double median_ms(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

DepthPeelMeasurement measure_depth_peel(const Mesh& mesh, const vk::DepthPeelConfig& config,
                                        const SdfOptions& options, int repeats) {
  DepthPeelMeasurement m;
  auto t0 = Clock::now();
  vk::DepthPeelBackend backend(config);
  auto t1 = Clock::now();
  m.construct_ms = ms(t0, t1);
  m.device = backend.device_name();

  t0 = Clock::now();
  backend.set_mesh(mesh);
  m.field = compute_sdf(backend, mesh, options);
  m.first_call_ms = ms(t0, Clock::now());
  m.points = m.field.values.size();

  for (int r = 0; r < repeats; ++r) {
    t0 = Clock::now();
    backend.update_positions(mesh.positions);
    m.field = compute_sdf(backend, mesh, options);
    m.repeat_ms.push_back(ms(t0, Clock::now()));
  }
  m.stages = backend.last_timings();
  m.layers = backend.last_layer_count();
  m.device_bytes = backend.device_memory_bytes();
  return m;
}

}  // namespace sdfkit::bench

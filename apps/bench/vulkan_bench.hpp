#pragma once
// Timing of the Vulkan depth-peeling backend, reusable by the shared benchmark: end-to-end wall
// time per call, per-stage times (and per-pass GPU times with profile), optional comparison
// with a reference field.

#include "sdfkit/core/sdf.hpp"
#include "sdfkit/vulkan/depth_peel.hpp"

#include <string>
#include <vector>

namespace sdfkit::bench {

struct DepthPeelMeasurement {
  std::string device;
  std::size_t points = 0;
  double construct_ms = 0.0;           // context + pipelines + images
  double first_call_ms = 0.0;          // set_mesh + compute, first time
  std::vector<double> repeat_ms;       // set_mesh(update_positions) + compute, warm
  std::vector<StageTiming> stages;     // of the last repeat
  int layers = 0;                      // deepest peel of the last call
  std::size_t device_bytes = 0;
  SdfField field;                      // of the last call
};

// Builds a backend with `config`, runs compute_sdf once cold and `repeats` times warm
// (update_positions with the same positions, as an iterative caller would).
DepthPeelMeasurement measure_depth_peel(const Mesh& mesh, const vk::DepthPeelConfig& config,
                                        const SdfOptions& options, int repeats);

double median_ms(std::vector<double> v);

}  // namespace sdfkit::bench

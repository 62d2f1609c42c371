// sdfkit-vulkan-bench: times the depth-peeling backend on mesh files, per stage and end to end,
// and (when built with the Embree reference) compares its field with the reference.
//
//   sdfkit-vulkan-bench [--views N] [--resolution N] [--batch N] [--layers-per-submit N]
//                       [--repeat N] [--profile] [--face] [--reference] [--print-graph]
//                       [--validation] mesh.off...

#include "vulkan_bench.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"
#include "sdfkit/io/asset.hpp"
#ifdef SDFKIT_BENCH_HAS_REFERENCE
#include "sdfkit/reference/embree_backend.hpp"
#endif

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

double pearson(const std::vector<float>& a, const std::vector<float>& b) {
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= a.size();
  mb /= b.size();
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0.0;
}

double median_rel(const std::vector<float>& a, const std::vector<float>& b) {
  std::vector<double> r;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (b[i] != 0.0f) r.push_back(std::fabs(a[i] - b[i]) / std::fabs(b[i]));
  if (r.empty()) return 0.0;
  std::sort(r.begin(), r.end());
  return r[r.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  sdfkit::vk::DepthPeelConfig cfg;
  cfg.views = 128;
  sdfkit::SdfOptions options;
  int repeats = 3;
  bool reference = false;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&] {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return std::atoi(argv[++i]);
    };
    if (a == "--views") cfg.views = next();
    else if (a == "--resolution") cfg.resolution = next();
    else if (a == "--batch") cfg.cameras_per_batch = next();
    else if (a == "--layers-per-submit") cfg.layers_per_submit = next();
    else if (a == "--repeat") repeats = next();
    else if (a == "--profile") cfg.profile = true;
    else if (a == "--validation") cfg.validation = true;
    else if (a == "--face") options.domain = sdfkit::SdfDomain::Face;
    else if (a == "--reference") reference = true;
    else if (a == "--print-graph") sdfkit::set_log_level(sdfkit::LogLevel::Debug);
    else files.push_back(a);
  }
  if (files.empty()) {
    std::fprintf(stderr, "usage: %s [options] mesh...\n", argv[0]);
    return 2;
  }
  try {
    for (const auto& f : files) {
      const sdfkit::io::Asset asset = sdfkit::io::load_asset(f);
      const auto m = sdfkit::bench::measure_depth_peel(asset.mesh, cfg, options, repeats);
      std::printf("%s: %zu points, device %s, views %d, resolution %d\n", f.c_str(), m.points, m.device.c_str(),
                  cfg.views, cfg.resolution);
      std::printf("  construct %.1f ms, first call %.1f ms, warm median %.1f ms (%zu repeats), layers %d, "
                  "device memory %.1f MiB\n",
                  m.construct_ms, m.first_call_ms, sdfkit::bench::median_ms(m.repeat_ms), m.repeat_ms.size(),
                  m.layers, m.device_bytes / 1048576.0);
      for (const auto& s : m.stages) std::printf("    %-22s %9.2f ms\n", s.stage.c_str(), s.milliseconds);
#ifdef SDFKIT_BENCH_HAS_REFERENCE
      if (reference) {
        sdfkit::reference::EmbreeBackend ref;
        ref.set_mesh(asset.mesh);
        const auto t0 = std::chrono::steady_clock::now();
        const sdfkit::SdfField r = sdfkit::compute_sdf(ref, asset.mesh, options);
        const double ref_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        std::vector<float> a, b;
        for (std::size_t i = 0; i < r.values.size(); ++i)
          if (!r.filled[i] && !m.field.filled[i]) {
            a.push_back(m.field.values[i]);
            b.push_back(r.values[i]);
          }
        std::printf("  vs Embree reference (%.1f ms): median relative difference %.4f, pearson %.4f (%zu points)\n",
                    ref_ms, median_rel(a, b), pearson(a, b), a.size());
      }
#else
      if (reference) std::printf("  (built without the Embree reference)\n");
#endif
    }
  } catch (const sdfkit::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}

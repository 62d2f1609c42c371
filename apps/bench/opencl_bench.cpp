// sdfkit-opencl-bench: times the OpenCL backend (and, when built, the Embree reference) on the
// same meshes: octree build, upload, trace+gather, rays per second, the cost of a repeated call
// (update_positions + compute) against the first (set_mesh + compute), peak memory.
//
//   sdfkit-opencl-bench [--rays 25,30] [--domain vertex|face] [--device SEL] [--no-embree]
//                       [--accel bvh|octree] [--bvh-leaf L]
//                       [--repeats N] [--depth D] [--leaf L] [--wg N] [--tube RINGS,SEGMENTS]
//                       [--json FILE] MESH...
//
// The timing logic is run_backend() below, written to be folded into sdfkit-bench.
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/opencl/opencl_backend.hpp"
#if SDFKIT_BENCH_HAS_EMBREE
#include "sdfkit/reference/embree_backend.hpp"
#endif

#include <CLI/CLI.hpp>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace sdfkit::bench {

// One timed backend on one mesh and option set.
struct TimedRun {
  std::string backend, device;
  double construct_ms = 0;     // creating the backend (context, program build)
  double first_ms = 0;         // set_mesh + compute on a fresh backend
  double repeat_ms = 0;        // update_positions (moved vertices) + compute, median of repeats
  double trace_ms = 0;         // the trace+gather stage of the best warm compute
  std::vector<StageTiming> first_stages, repeat_stages;
  double rays_per_second = 0;  // valid points * rays / trace_ms
  double compute_cpu_ms = 0;   // process CPU time (all threads) of the best warm compute()
  double rays_per_cpu_second = 0;  // valid points * rays / compute_cpu_ms: on a shared machine
                                   // less sensitive to other load than wall-clock time
  std::size_t device_bytes = 0;
  std::size_t points = 0, rays = 0;
};

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

// CPU time of this process, all threads, milliseconds.
double cpu_ms() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return (static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) * 1e3 +
          static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-3);
}

double stage(const std::vector<StageTiming>& stages, const std::string& name) {
  for (const StageTiming& s : stages)
    if (s.stage == name) return s.milliseconds;
  return 0.0;
}

// Times `make` (backend construction), set_mesh + compute (first call), `repeats` warm calls of
// update_positions (vertices jittered by 1e-4 of the diagonal) + compute; trace time is the best
// warm compute's "trace_gather" stage.
TimedRun run_backend(const std::function<std::unique_ptr<SdfBackend>()>& make, const Mesh& mesh,
                     const SdfOptions& options, int repeats) {
  TimedRun r;
  auto t = std::chrono::steady_clock::now();
  std::unique_ptr<SdfBackend> backend = make();
  r.construct_ms = ms_since(t);
  r.backend = backend->name();
  r.device = backend->device_name();
  const SdfQuery query = make_query(mesh, options.domain);
  r.points = static_cast<std::size_t>(std::count(query.valid.begin(), query.valid.end(), 1));
  r.rays = r.points * static_cast<std::size_t>(options.rays);

  t = std::chrono::steady_clock::now();
  backend->set_mesh(mesh);
  (void)backend->compute(query, options);
  r.first_ms = ms_since(t);
  r.first_stages = backend->last_timings();
  double best_trace = stage(r.first_stages, "trace_gather");

  std::mt19937 rng(1);
  const float jitter = 1e-4f * bounding_box(mesh.positions).diagonal();
  std::uniform_real_distribution<float> u(-jitter, jitter);
  std::vector<double> repeat;
  double best_cpu = 0.0;
  for (int i = 0; i < repeats; ++i) {
    std::vector<glm::vec3> moved = mesh.positions;
    for (glm::vec3& p : moved) p += glm::vec3(u(rng), u(rng), u(rng));
    Mesh m2{moved, mesh.triangles};
    const SdfQuery q2 = make_query(m2, options.domain);  // the caller's work, not timed
    t = std::chrono::steady_clock::now();
    backend->update_positions(moved);
    const double c0 = cpu_ms();
    (void)backend->compute(q2, options);
    const double c = cpu_ms() - c0;
    best_cpu = i == 0 ? c : std::min(best_cpu, c);
    repeat.push_back(ms_since(t));
    r.repeat_stages = backend->last_timings();
    best_trace = std::min(best_trace, stage(r.repeat_stages, "trace_gather"));
  }
  if (!repeat.empty()) {
    std::sort(repeat.begin(), repeat.end());
    r.repeat_ms = repeat[repeat.size() / 2];
  }
  r.trace_ms = best_trace;
  r.rays_per_second = best_trace > 0 ? static_cast<double>(r.rays) / (best_trace * 1e-3) : 0.0;
  r.compute_cpu_ms = best_cpu;
  r.rays_per_cpu_second = best_cpu > 0 ? static_cast<double>(r.rays) / (best_cpu * 1e-3) : 0.0;
  r.device_bytes = backend->device_memory_bytes();
  return r;
}

std::size_t peak_rss_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<std::size_t>(u.ru_maxrss) * 1024;
}

}  // namespace sdfkit::bench

int run(int argc, char** argv);

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sdfkit-opencl-bench: %s\n", e.what());
    return 1;
  }
}

int run(int argc, char** argv) {
  using namespace sdfkit;
  CLI::App app{"Times the OpenCL SDF backend against the Embree reference"};
  std::vector<std::string> meshes;
  std::vector<int> rays_list{25, 30};
  std::string domain = "vertex", device, json_path;
  std::vector<int> tube;
  int repeats = 3;
  bool no_embree = false;
  cl::OpenClConfig config;
  app.add_option("meshes", meshes, "Mesh files (OFF, OBJ, PLY, glTF)");
  app.add_option("--rays", rays_list, "Rays per point")->delimiter(',');
  app.add_option("--domain", domain, "vertex or face")->check(CLI::IsMember({"vertex", "face"}));
  app.add_option("--device", config.device, "OpenCL device: index or name substring");
  app.add_option("--repeats", repeats, "Warm update_positions + compute calls");
  std::string accel = "bvh";
  app.add_option("--accel", accel, "bvh or octree")->check(CLI::IsMember({"bvh", "octree"}));
  app.add_option("--bvh-leaf", config.bvh_leaf_size, "BVH leaf triangle limit");
  bool no_packets = false, force_packets = false;
  app.add_flag("--no-packets", no_packets, "BVH: one ray per work item instead of packets of 8");
  app.add_flag("--packets", force_packets, "BVH: packets of 8 rays even on a GPU");
  app.add_option("--depth", config.octree_max_depth, "Octree max depth");
  app.add_option("--leaf", config.octree_leaf_size, "Octree leaf triangle limit");
  app.add_option("--wg", config.work_group_size, "Trace work-group size (0 = driver)");
  app.add_option("--memory-cap", config.memory_cap, "Per-batch device memory cap, bytes");
  app.add_option("--tube", tube, "Also run a generated swept tube of RINGS,SEGMENTS")->delimiter(',')->expected(2);
  app.add_flag("--no-embree", no_embree, "Skip the Embree reference");
  app.add_option("--json", json_path, "Write the results as JSON");
  CLI11_PARSE(app, argc, argv);
  config.accel = accel == "octree" ? cl::Accel::Octree : cl::Accel::Bvh;
  if (no_packets) config.bvh_packets = false;
  if (force_packets) config.bvh_packets = true;
  if (accel == "bvh" && no_packets) accel = "bvh-single";

  struct Named {
    std::string name;
    Mesh mesh;
  };
  std::vector<Named> inputs;
  for (const std::string& path : meshes) inputs.push_back({path, io::load_asset(path).mesh});
  if (tube.size() == 2) {
    auto t = std::chrono::steady_clock::now();
    Mesh m = shapes::swept_tube(2.0f, 20.0f, tube[0], tube[1]).mesh;
    std::fprintf(stderr, "generated tube %zu faces in %.0f ms\n", m.triangles.size(), bench::ms_since(t));
    inputs.push_back({"swept_tube_" + std::to_string(tube[0]) + "x" + std::to_string(tube[1]), std::move(m)});
  }

  std::ostringstream json;
  json << "[\n";
  bool first_json = true;
  std::printf("| mesh | faces | backend | rays | setup ms | first ms | repeat ms | octree/bvh ms | upload ms | trace ms | Mrays/s | Mrays/CPU-s | device MiB | peak RSS MiB |\n");
  std::printf("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const Named& in : inputs) {
    for (int rays : rays_list) {
      SdfOptions o;
      o.rays = rays;
      o.domain = domain == "face" ? SdfDomain::Face : SdfDomain::Vertex;
      std::vector<std::pair<std::string, std::function<std::unique_ptr<SdfBackend>()>>> makers;
      makers.emplace_back("opencl-" + accel, [&] { return std::make_unique<cl::OpenClBackend>(config); });
#if SDFKIT_BENCH_HAS_EMBREE
      if (!no_embree)
        makers.emplace_back("embree", [] { return std::make_unique<reference::EmbreeBackend>(); });
#endif
      for (const auto& [label, make] : makers) {
        const bench::TimedRun r = bench::run_backend(make, in.mesh, o, repeats);
        const auto& st = r.repeat_stages.empty() ? r.first_stages : r.repeat_stages;
        const double build = bench::stage(st, "octree_build") + bench::stage(st, "bvh_build");
        std::printf("| %s | %zu | %s | %d | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.2f | %.2f | %.1f | %.0f |\n",
                    in.name.c_str(), in.mesh.triangles.size(), label.c_str(), rays, r.construct_ms, r.first_ms,
                    r.repeat_ms, build, bench::stage(st, "upload"), r.trace_ms,
                    r.rays_per_second * 1e-6, r.rays_per_cpu_second * 1e-6,
                    static_cast<double>(r.device_bytes) / (1 << 20),
                    static_cast<double>(bench::peak_rss_bytes()) / (1 << 20));
        std::fflush(stdout);
        json << (first_json ? "" : ",\n") << "  {\"mesh\": \"" << in.name << "\", \"faces\": "
             << in.mesh.triangles.size() << ", \"backend\": \"" << label << "\", \"device\": \""
             << r.device << "\", \"rays\": " << rays << ", \"construct_ms\": " << r.construct_ms
             << ", \"first_ms\": " << r.first_ms << ", \"repeat_ms\": " << r.repeat_ms
             << ", \"build_ms\": " << build << ", \"upload_ms\": " << bench::stage(st, "upload")
             << ", \"trace_ms\": " << r.trace_ms << ", \"rays_per_second\": " << r.rays_per_second
             << ", \"rays_per_cpu_second\": " << r.rays_per_cpu_second
             << ", \"device_bytes\": " << r.device_bytes << ", \"peak_rss_bytes\": "
             << bench::peak_rss_bytes() << "}";
        first_json = false;
      }
    }
  }
  json << "\n]\n";
  if (!json_path.empty()) std::ofstream(json_path) << json.str();
  return 0;
}

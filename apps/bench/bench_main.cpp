// sdfkit-bench: the paper's Table 1 on this machine. Times the Vulkan and OpenCL backends, the
// Embree reference, CGAL's sdf_values and (with --meshlab) MeshLab's GPU SDF filter on the same
// meshes in one run; writes Markdown and JSON.
#include "batch_bench.hpp"
#include "bench_runner.hpp"
#include "diffusion_bench.hpp"
#include "huge_bench.hpp"

#include "sdfkit/io/asset.hpp"
#include "sdfkit/process.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace sdfkit::bench;

namespace {

std::string cpu_name() {
  std::ifstream f("/proc/cpuinfo");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown CPU";
}

std::string self_dir() {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return ".";
  buf[n] = 0;
  return fs::path(buf).parent_path().string();
}

}  // namespace

int main(int argc, char** argv) {
  sdfkit::keep_freed_heap();
  CLI::App app{"sdfkit-bench: time the SDF backends against the Embree reference, CGAL and MeshLab"};
  BenchOptions o;
  std::vector<std::string> meshes;
  std::string json_out, md_out, work = "bench-work";
  bool large = false, no_cgal = false, huge = false, generate_only = false;
  HugeOptions huge_options;
  app.add_option("MESHES", meshes, "Meshes to time (default: CGAL's elephant, armadillo, bunny00, refined_elephant)");
  app.add_option("--backends", o.backends, "Backends: vulkan opencl embree")->delimiter(',');
  app.add_option("--rays", o.rays, "Rays per point for the ray backends");
  app.add_option("--views", o.views, "Vulkan views (0 = default)");
  app.add_option("--resolution", o.resolution, "Vulkan resolution (0 = default)");
  app.add_option("--vulkan-mode", o.vulkan_mode, "Vulkan peel mode: layers (the paper's) | lists (fragment lists)")
      ->check(CLI::IsMember({"layers", "lists"}));
  app.add_option("--repeats", o.repeats, "Warm repeats per backend");
  app.add_option("--device", o.device, "GPU device selector");
  app.add_flag("--profile", o.profile, "Per-pass GPU timestamps (Vulkan) in the stage table");
  app.add_flag("--large", large, "Add bunny00 subdivided (~150k vertices) and armadillo subdivided twice (~416k)");
  app.add_flag("--huge", huge,
               "Instead of the table: CGAL's armadillo subdivided to levels 3 and 4 (3.3M, 13.3M triangles) as binary "
               "PLY and OBJ, each through `sdfkit compute --json` in its own process: time and peak memory per stage");
  bool diffusion = false;  // issue 13
  DiffusionBenchOptions diffusion_options;
  app.add_flag("--diffusion", diffusion,
               "Table 2: texture-space diffusion at radius 2..64 px on a 2048² atlas and k-ring k = 1..6 "
               "(a full-atlas cylinder of ~500k vertices, CGAL's elephant, armadillo, bunny00 and armadillo subdivided twice)");
  app.add_option("--radii", diffusion_options.radii, "--diffusion: blur radii in texels")->delimiter(',')->check(CLI::PositiveNumber);
  app.add_option("--atlas-size", diffusion_options.atlas_size, "--diffusion: atlas side in texels")->check(CLI::Range(16, 16384));
  app.add_option("--huge-levels", huge_options.levels, "--huge: subdivision levels")->delimiter(',')->check(CLI::Range(0, 6));
  app.add_option("--huge-formats", huge_options.formats, "--huge: ply, obj")->delimiter(',');
  app.add_option("--huge-backend", huge_options.backend, "--huge: the backend of the runs");
  app.add_flag("--generate-only", generate_only, "--huge: only write the meshes");
  BatchBenchOptions batch_options;
  app.add_option("--batch", batch_options.assets,
                 "Instead of the table: N cow-sized assets through one `sdfkit batch` (issue 15): wall, CPU, per-asset stages")
      ->check(CLI::Range(1, 1000000));
  app.add_option("--batch-jobs", batch_options.jobs, "--batch: batch -j")->check(CLI::Range(1, 64));
  app.add_option("--batch-backend", batch_options.backend, "--batch: batch --backend (auto, vulkan, opencl)");
  app.add_option("--batch-format", batch_options.format, "--batch: batch --format")->check(CLI::IsMember({"glb", "gltf", "ply", "txt"}));
  app.add_flag("--meshlab", o.meshlab, "Also time MeshLab's GPU SDF filter (meshlabserver, xvfb-run)");
  app.add_flag("--no-cgal", no_cgal, "Skip CGAL's sdf_values");
  app.add_option("--smooth", o.smooth_rings, "k of the k-ring smoothing timing (0 = off)");
  app.add_option("--work-dir", work, "Where meshes and temporary files go");
  app.add_option("--json", json_out, "Write results as JSON");
  app.add_option("--markdown", md_out, "Write the Markdown table");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;  // help and version succeed; every usage error is 2, as in sdfkit
  }
  o.cgal = !no_cgal;
  o.cgal_helper = self_dir() + "/sdfkit-cgal-sdf";
  if (o.cgal && !fs::exists(o.cgal_helper)) {
    std::fprintf(stderr, "sdfkit-bench: CGAL helper not built (install libcgal-dev: scripts/install-deps.sh --bench); skipping CGAL\n");
    o.cgal = false;
  }

  try {
    fs::create_directories(work);
    // The special modes print a Markdown table and write it and their JSON where asked.
    const auto emit = [&](const std::string& table, nlohmann::json& j) {
      const std::string md = "Machine: " + cpu_name() + ", " + std::to_string(std::thread::hardware_concurrency()) +
                             " hardware threads.\n\n" + table;
      std::printf("%s", md.c_str());
      if (!md_out.empty()) sdfkit::io::write_file_atomically(md_out, [&](std::ostream& os) { os << md; });
      if (!json_out.empty()) {
        j["machine"] = cpu_name();
        sdfkit::io::write_file_atomically(json_out, [&](std::ostream& os) { os << j.dump(2) << '\n'; });
      }
      return 0;
    };
    if (app.count("--batch") > 0) {
      batch_options.work_dir = work;
      batch_options.rays = o.rays;
      batch_options.sdfkit = self_dir() + "/sdfkit";
      if (!fs::exists(batch_options.sdfkit)) batch_options.sdfkit = self_dir() + "/../sdfkit";
      std::string table;
      auto j = run_batch_bench(batch_options, table);
      return emit(table, j);
    }
    if (diffusion) {
      // Each blur cell is a difference of two graph runs' wall times: 5 pairs by default, so that
      // its median and quartiles stand against this shared VM's noise.
      if (app.count("--repeats") > 0) diffusion_options.repeats = std::max(o.repeats, 1);
      diffusion_options.device = o.device;
      std::vector<DiffusionMesh> dm;
      dm.push_back(cylinder_mesh(1000, 499, diffusion_options.atlas_size));
      if (meshes.empty()) {
        for (BenchMesh& m : default_meshes(work, false))
          if (m.name != "refined_elephant") dm.push_back({m.name, std::move(m.mesh), {}, {}});
        DiffusionMesh big;
        big.name = "armadillo-subdiv2";
        big.base = dm[2].mesh;
        big.mesh = sdfkit::subdivide_midpoint(sdfkit::subdivide_midpoint(dm[2].mesh));
        dm.push_back(std::move(big));
      } else {
        for (const auto& path : meshes) {
          BenchMesh m = load_mesh(path, work);
          dm.push_back({m.name, std::move(m.mesh), {}, {}});
        }
      }
      std::string table;
      auto j = run_diffusion_bench(dm, diffusion_options, table);
      return emit(table, j);
    }
    if (huge) {
      huge_options.work_dir = work;
      huge_options.rays = o.rays;
      huge_options.sdfkit = self_dir() + "/sdfkit";
      if (!fs::exists(huge_options.sdfkit)) huge_options.sdfkit = self_dir() + "/../sdfkit";
      if (generate_only) {
        generate_huge_meshes(huge_options);
        return 0;
      }
      std::string table;
      auto j = run_huge(huge_options, table);
      return emit(table, j);
    }
    std::vector<BenchMesh> list;
    if (meshes.empty())
      list = default_meshes(work, large);
    else
      for (const auto& m : meshes) list.push_back(load_mesh(m, work));

    std::vector<MeshResult> results;
    for (const BenchMesh& m : list) {
      std::fprintf(stderr, "sdfkit-bench: %s (%zu vertices, %zu faces)\n", m.name.c_str(), m.mesh.positions.size(),
                   m.mesh.triangles.size());
      results.push_back(run_mesh(m, o));
    }
    std::ostringstream header;
    header << "Machine: " << cpu_name() << ", " << std::thread::hardware_concurrency() << " hardware threads";
    std::set<std::string> devices;
    for (const auto& r : results)
      for (const auto& b : r.runs)
        if (b.error.empty() && devices.insert(b.backend + " on " + b.device).second)
          header << "; " << b.backend << " on " << b.device;
    header << ".\n\n";
    const std::string md = header.str() + to_markdown(results, o);
    std::printf("%s", md.c_str());
    if (!md_out.empty()) sdfkit::io::write_file_atomically(md_out, [&](std::ostream& os) { os << md; });
    if (!json_out.empty()) {
      auto j = to_json(results, o);
      j["machine"] = header.str();
      sdfkit::io::write_file_atomically(json_out, [&](std::ostream& os) { os << j.dump(2) << '\n'; });
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sdfkit-bench: error: %s\n", e.what());
    return 1;
  }
  return 0;
}

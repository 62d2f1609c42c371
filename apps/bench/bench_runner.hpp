#pragma once
// The benchmark runner behind sdfkit-bench: times backends on meshes and collects a table.

#include "sdfkit/backends.hpp"
#include "sdfkit/core/mesh.hpp"
#include "sdfkit/post/compare.hpp"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace sdfkit::bench {

struct BenchMesh {
  std::string name;
  Mesh mesh;
  std::string off_path;  // the mesh as an OFF file, for CGAL and MeshLab
};

struct BenchOptions {
  // vulkan, opencl (BVH), opencl-octree, embree
  std::vector<std::string> backends = {"vulkan", "opencl", "embree"};
  int rays = 30;             // ray backends' default table
  int cgal_rays = 25;        // the CGAL comparison (per face)
  int views = 0, resolution = 0;  // Vulkan (0 = backend default)
  std::string vulkan_mode;        // Vulkan: "layers" | "lists" ("" = backend default)
  int meshlab_views = 128, meshlab_resolution = 512;
  int repeats = 3;           // warm calls after the first; the median is reported
  bool cgal = true;
  bool meshlab = false;
  int smooth_rings = 2;
  std::string cgal_helper;   // path of sdfkit-cgal-sdf ("" = next to this program)
  std::string device;        // device selector passed to the GPU backends
  bool profile = false;      // per-pass GPU timestamps (Vulkan) in the stage table
};

struct BackendRun {
  std::string backend, device, mode;  // mode: "vertex/30 rays", "face/25 rays", "vertex/128 views 512px"
  double session_ms = 0;     // creating the backend session (device, programs, pipelines)
  double first_ms = 0;       // set_mesh + compute, cold
  double repeat_ms = 0;      // update_positions (or set_mesh) + compute, median of repeats
  double repeat_cpu_ms = 0;  // process CPU time (all threads) of the median warm call
  std::vector<StageTiming> stages;  // of the last call
  double rays_per_second = 0;  // ray backends: valid points * rays / trace time
  std::size_t device_bytes = 0;  // the session's device buffers (backend's own count)
  double peak_rss_mib = 0;       // the process's peak resident memory after this run
  std::optional<FieldComparison> vs_reference;
  std::string error;
};

struct MeshResult {
  std::string name;
  std::size_t vertices = 0, faces = 0;
  std::vector<BackendRun> runs;
  std::optional<double> cgal_seconds, cgal_cpu_seconds, meshlab_seconds, smooth_ms;
  std::string cgal_error, meshlab_error;
};

// Loads the default meshes: CGAL's data set (elephant, armadillo, refined_elephant, bunny00)
// plus bunny00 subdivided to ~150k vertices and armadillo to ~416k (the paper's Buddha and
// Gargoyle sizes). OFF copies are written under work_dir.
std::vector<BenchMesh> default_meshes(const std::string& work_dir, bool large);
BenchMesh load_mesh(const std::string& path, const std::string& work_dir);

MeshResult run_mesh(const BenchMesh& mesh, const BenchOptions& options);

nlohmann::json to_json(const std::vector<MeshResult>& results, const BenchOptions& options);
std::string to_markdown(const std::vector<MeshResult>& results, const BenchOptions& options);

}  // namespace sdfkit::bench

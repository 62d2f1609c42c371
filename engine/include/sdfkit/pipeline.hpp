#pragma once
// The straight road: load a file, compute its SDF with a backend, post-process, write atomically.
// Shared by `sdfkit compute`, `sdfkit batch` and embedding tools.

#include "sdfkit/backends.hpp"
#include "sdfkit/core/sdf.hpp"
#include "sdfkit/io/asset.hpp"

#include <functional>
#include <string>
#include <vector>

namespace sdfkit {

// Loads a mesh file, or a generated shape named "builtin:NAME" (see builtin_names()): the
// paper's Figure 7 tube is the bundled default input of the demo.
io::Asset load_input(const std::string& path, const io::LoadOptions& options = {});
std::string builtin_names();

struct ComputeRequest {
  std::string input;
  std::string output;               // format by extension; "" = do not write
  io::LoadOptions load;
  SdfOptions sdf;
  io::WriteOptions write;
  int smooth_rings = 0;             // k-ring Gaussian smoothing of the result, 0 = off
};

struct FieldSummary {
  float min = 0, max = 0, mean = 0, median = 0;
};
FieldSummary summarize(std::span<const float> values);

// This process's resident memory (Linux /proc/self/status: VmRSS, and its peak so far VmHWM),
// MiB; zeros where the system does not say.
struct ResidentMemory {
  double rss_mib = 0, peak_rss_mib = 0;
};
ResidentMemory resident_memory();

// The resident memory after one step of a run.
struct StageMemory {
  std::string stage;
  ResidentMemory memory;
};

struct ComputeReport {
  std::string input, output;
  std::size_t input_vertices = 0, input_faces = 0, welded_vertices = 0, points = 0;
  std::string backend, device;
  std::vector<StageTiming> stages;  // load (nested: read, weld), each backend stage, smooth, write
  // After each step: read, weld, device, set_mesh (BVH or octree build, upload), sdf (trace),
  // smooth, write. The peak is the process's so far, so a step's own peak shows where it grows.
  std::vector<StageMemory> memory;
  std::size_t filled_points = 0;    // points with no accepted ray, filled from neighbours
  FieldSummary summary;
  std::vector<std::string> warnings;
};

// JSON text of a report: the record of `compute --json` and of each `batch` asset. `error`
// non-empty marks a failed job; `fingerprint` identifies the options and input it was made with.
std::string report_to_json(const ComputeReport& report, const std::string& error = {},
                           const std::string& fingerprint = {});

// Runs one job on an existing backend session (reused across jobs). Throws Error on failure;
// nothing is written unless everything before the write succeeded.
ComputeReport run_compute(const ComputeRequest& request, SdfBackend& backend);

// The same, with the backend made on first use, after the input loaded: a bad file is reported
// before any device is opened.
using BackendProvider = std::function<SdfBackend&()>;
ComputeReport run_compute(const ComputeRequest& request, const BackendProvider& backend);

}  // namespace sdfkit

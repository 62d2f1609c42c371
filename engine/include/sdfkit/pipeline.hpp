#pragma once
// The straight road: load a file, compute its SDF with a backend, post-process, write atomically.
// Shared by `sdfkit compute`, `sdfkit batch` and embedding tools.

#include "sdfkit/backends.hpp"
#include "sdfkit/core/sdf.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/session.hpp"

#include <functional>
#include <string>
#include <vector>

namespace sdfkit {

// Loads a mesh file, or a generated shape named "builtin:NAME" (see builtin_names()): the
// paper's Figure 7 tube is the bundled default input of the demo.
io::Asset load_input(const std::string& path, const io::LoadOptions& options = {});
std::string builtin_names();

// One job and every option that decides its result. options_to_json() writes all of them:
// the batch's resume fingerprint and the reports' "options" are that one serialisation.
struct ComputeRequest {
  std::string input;
  std::string output;               // format by extension; "" = do not write
  io::LoadOptions load;
  SdfOptions sdf;
  io::WriteOptions write;
  int smooth_rings = 0;             // k-ring Gaussian smoothing of the result, 0 = off
  // Texture-space diffusion of the result (issue 13): the Gaussian's sigma in texels of a 2048²
  // skeleton texture mapping, 0 = off. Per-vertex results only; not with smooth_rings.
  float smooth_texture_px = 0.0f;
  BackendConfig backend;            // the session run_compute opens when it is not given one
};

// The one place a request's options are validated: ranges (rays, cone, smoothing, welding) and
// the backend contract (check_backend_options). Throws UsageError.
void validate(const ComputeRequest& request);

// Every option of `request` (not input and output) as one JSON object, keys sorted: backend
// {kind, auto_order, device, views, resolution, peel_mode, profile, validation, memory_cap,
// accel}, sdf {rays, cone_degrees, per, false_hits}, load {...}, write {...}, smooth_rings.
std::string options_to_json(const ComputeRequest& request);

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
  std::string backend_choice;       // why this backend (BackendChoice::reason)
  std::string options;              // options_to_json of the request
  std::vector<StageTiming> stages;  // load (nested: read, weld), each backend stage, smooth, write
  // After each step: read, weld, device, set_mesh (BVH or octree build, upload), sdf (trace),
  // smooth, write. The peak is the process's so far, so a step's own peak shows where it grows.
  std::vector<StageMemory> memory;
  std::size_t filled_points = 0;    // points with no accepted ray, filled from neighbours
  // The asset's solids (io/solids.hpp: a glTF node drawing a mesh is one) and the SDF
  // computations they took: one per (mesh, similarity class).
  std::size_t solids = 1, sdf_computations = 1;
  FieldSummary summary;
  std::vector<std::string> warnings;
};

// JSON text of a report: the record of `compute --json` and of each `batch` asset. `error`
// non-empty marks a failed job; `fingerprint` identifies the options and input it was made with.
std::string report_to_json(const ComputeReport& report, const std::string& error = {},
                           const std::string& fingerprint = {});

// The session a job runs on, asked for after the input loaded: a bad file is reported before
// any device is opened.
using SessionProvider = std::function<Session&()>;

// A job's loaded asset and finished field, not written (render, the Python module).
struct ComputeResult {
  ComputeReport report;
  io::Asset asset;
  SdfField field;                   // smoothed when request.smooth_rings > 0
};
ComputeResult compute_asset(const ComputeRequest& request, const SessionProvider& session);
// The same on an asset the caller loaded already (request.input only names it in the report).
ComputeResult compute_asset(const ComputeRequest& request, io::Asset asset, const SessionProvider& session);

// Runs one job: validate, load, compute, smooth, write atomically; nothing is written unless
// everything before the write succeeded. Throws Error on failure. On a given session (reused
// across jobs; its mesh is replaced), through a provider, or on a session opened from
// request.backend after the input loaded.
ComputeReport run_compute(const ComputeRequest& request, Session& session);
ComputeReport run_compute(const ComputeRequest& request, const SessionProvider& session);
ComputeReport run_compute(const ComputeRequest& request);

}  // namespace sdfkit

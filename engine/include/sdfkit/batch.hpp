#pragma once
// Batch processing of many assets: expand inputs (files, directories, manifests), split them
// into shards for an external scheduler, run several assets in flight, write each result
// atomically beside a per-asset JSON record, and skip assets already done (resume).

#include "sdfkit/pipeline.hpp"

#include <functional>
#include <string>
#include <vector>

namespace sdfkit {

// Expands inputs into a sorted, de-duplicated list of mesh files: a file is taken as is; a
// directory is searched recursively for .gltf .glb .obj .off .ply; a file ending in .list,
// .manifest or .txt, or any "@FILE", is a manifest: one path per line ('#' comments, blank lines
// ignored, relative paths relative to the manifest). Inside a manifest a line "@FILE" is a
// manifest too, FILE relative to the listing manifest (a file whose name starts with '@' is
// listed as "./@name"). Throws InputError for a missing input.
std::vector<std::string> expand_inputs(const std::vector<std::string>& inputs);

// Shard `index` of `count` (0 <= index < count): every count-th input starting at index of the
// sorted list, so shards are disjoint, cover everything, and do not depend on the machine.
std::vector<std::string> select_shard(const std::vector<std::string>& sorted_inputs, int index, int count);

// Parses "I/N" (throws UsageError).
std::pair<int, int> parse_shard(const std::string& text);

struct BatchOptions {
  std::string out_dir;
  std::string format = "glb";      // output extension: glb gltf ply txt
  int jobs = 2;                    // assets in flight (each with its own backend session)
  bool force = false;              // recompute assets whose result is complete
  // Every option of the result (backend, sdf, load, write, smoothing); input and output are set
  // per asset. Its options_to_json is the resume fingerprint, with the input's size and time.
  ComputeRequest base;
  std::string report_name = "batch-report.json";  // final report, inside out_dir
};

enum class AssetStatus { Done, Skipped, Failed };

struct AssetOutcome {
  std::string input, output, record;  // record: the per-asset JSON file
  AssetStatus status = AssetStatus::Failed;
  std::string error;
  double seconds = 0;
  // Where the asset's time went (ms): the run's stages (load, read, weld, device, the backend's
  // build/upload/trace, smooth, write), "record" (its JSON record, written and fsynced) and
  // "other" (the rest of `seconds`: query, gap filling, reporting).
  std::vector<StageTiming> stages;
};

// Where a batch's time went.
struct BatchTiming {
  double wall_ms = 0;       // run_batch from start to the final report
  double plan_ms = 0;       // output names, fingerprints, the resume check of every input
  double cleanup_ms = 0;    // removing temporary files a killed run left
  double sessions_ms = 0;   // opening the worker sessions (devices, kernels/pipelines), once
  int sessions = 0;         // backend sessions opened: one per worker, never one per asset
  // The mean of each stage over the assets computed, in order of first appearance (ms).
  std::vector<StageTiming> mean_stages;
};

struct BatchSummary {
  std::vector<AssetOutcome> assets;  // in input order
  std::size_t done = 0, skipped = 0, failed = 0;
  std::size_t stale_temporaries = 0; // *.tmp-* files of a killed run removed before the work
  BatchTiming timing;
  std::string report;                // path of the final JSON report
};

// Called after each asset (from worker threads, serialised): finished count, total, outcome.
using BatchProgress = std::function<void(std::size_t, std::size_t, const AssetOutcome&)>;

// Output path of an input inside out_dir: <stem>.<format>, or <stem>-<hash>.<format> when two
// inputs share a stem.
std::vector<std::string> plan_outputs(const std::vector<std::string>& inputs, const std::string& out_dir,
                                      const std::string& format);

// Runs the batch. Temporary files a killed run left beside this batch's outputs, records and
// report (NAME.tmp-XXXXXXXX, see io::write_file_atomically) are removed first; only those of
// this batch's own assets, so a concurrent shard writing into the same directory is not
// disturbed. Throws UsageError for bad options and DeviceError before any work when no
// backend can be created; a bad asset is recorded as Failed and the batch goes on. An asset is
// skipped as complete when its output exists and its record says ok with the same fingerprint
// (batch_fingerprint: every option of options.base, the input's size and modification time).
std::string batch_fingerprint(const std::string& input, const BatchOptions& options);
BatchSummary run_batch(const std::vector<std::string>& inputs, const BatchOptions& options,
                       const BatchProgress& progress = {});

}  // namespace sdfkit

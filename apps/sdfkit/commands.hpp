#pragma once
// Subcommands of the sdfkit CLI. Each add_* registers its options and a callback on `app`.

#include <CLI/CLI.hpp>

#include "sdfkit/pipeline.hpp"

#include <string>

namespace sdfkit::cli {

void add_info_command(CLI::App& app);
void add_compute_command(CLI::App& app);
void add_devices_command(CLI::App& app);
void add_batch_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_skeleton_command(CLI::App& app);
void add_smooth_command(CLI::App& app);
void add_compare_command(CLI::App& app);
void add_pointcloud_skeleton_command(CLI::App& app);  // issue 14
void add_compress_animation_command(CLI::App& app);   // issue 14
#ifdef SDFKIT_CLI_HAS_RENDER
void add_render_command(CLI::App& app);
#endif

// The options every SDF-computing command shares (compute, batch, skeleton, render).
struct SdfCliOptions {
  std::string backend = "auto";
  std::string per = "vertex";
  std::string false_hits = "paper";
  SdfOptions sdf;
  BackendConfig backend_config;
  io::LoadOptions load;
  io::WriteOptions write;
  bool no_color = false;
  int smooth = 0;
  float smooth_texture = 0.0f;  // --smooth-texture R (issue 13)
  // Every option above as the pipeline's request (input and output empty).
  ComputeRequest request() const;
};
// How the SDF is computed: backend, device, sampling, Vulkan and OpenCL settings, welding.
// `views_flag` names the Vulkan camera count (render uses --views for its figure).
void add_sdf_options(CLI::App& cmd, SdfCliOptions& o, const std::string& views_flag = "--views");
// --allow-external-paths, --max-triangles, --max-file-size into `load` (untrusted assets).
void add_asset_options(CLI::App& cmd, io::LoadOptions& load);
// How results are written: --normalize, --no-color, and with `smoothing` --smooth K.
void add_output_options(CLI::App& cmd, SdfCliOptions& o, bool smoothing);
// Resolves the parsed strings into o.sdf / o.backend_config / o.write and validates the whole
// request once (sdfkit::validate: throws UsageError, exit 2).
void finish_sdf_options(SdfCliOptions& o);
// "backend opencl on DEVICE (why it was chosen)" for run summaries.
std::string backend_line(const ComputeReport& report);

// A result's values on its welded mesh (render, compare, smooth).
struct ResultValues {
  io::Asset asset;
  SdfDomain domain = SdfDomain::Vertex;
  std::vector<float> values;  // per welded vertex or per face of asset.mesh
  bool computed = false;      // the file held no values: computed with the SDF options
  ComputeReport report;       // when computed: the pipeline's report
};
// Reads a result file (read_field); with `sdf`, a file without values (or builtin:NAME) is
// computed instead through the pipeline (compute_asset, as `sdfkit compute`), and o.smooth > 0
// smooths the values. Without `sdf`, values are required.
ResultValues load_or_compute(const std::string& input, const SdfCliOptions* sdf,
                             const io::LoadOptions& load = {});
// Writes `text` to `path` through a temporary file beside it (never a half-written output).
void write_text_atomically(const std::string& path, const std::string& text);
// Throws InputError unless `path` ends in .png (any case).
void check_png_name(const std::string& path);

}  // namespace sdfkit::cli

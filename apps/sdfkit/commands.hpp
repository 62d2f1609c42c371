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
};
void add_sdf_options(CLI::App& cmd, SdfCliOptions& o);
// Resolves the parsed strings into o.sdf / o.backend_config / o.write (throws InputError).
void finish_sdf_options(SdfCliOptions& o);

}  // namespace sdfkit::cli

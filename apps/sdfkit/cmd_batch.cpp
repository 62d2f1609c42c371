#include "commands.hpp"

#include "sdfkit/batch.hpp"
#include "sdfkit/core/error.hpp"

#include <unistd.h>

#include <cstdio>
#include <memory>

namespace sdfkit::cli {

void add_batch_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("batch", "Compute the SDF of many assets: files, directories, manifests");
  struct Args {
    std::vector<std::string> inputs;
    std::string out_dir, format = "glb", shard;
    int jobs = 2;
    bool force = false;
    SdfCliOptions sdf;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("INPUT", a->inputs,
                  "Mesh files, directories (searched recursively), manifests (*.list, *.manifest, *.txt or @FILE: one path per line)")
      ->required();
  cmd->add_option("--out", a->out_dir, "Output directory (results and per-asset JSON records)")->required();
  cmd->add_option("--format", a->format, "Output format: glb gltf ply txt")->check(CLI::IsMember({"glb", "gltf", "ply", "txt"}));
  cmd->add_option("-j,--jobs", a->jobs, "Assets in flight")->check(CLI::Range(1, 64));
  cmd->add_option("--shard", a->shard, "Process only shard I of N (I/N, 0-based), e.g. $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT");
  cmd->add_flag("--force", a->force, "Recompute assets whose result is already complete");
  add_sdf_options(*cmd, a->sdf);
  add_output_options(*cmd, a->sdf, true);
  cmd->callback([a] {
    finish_sdf_options(a->sdf);
    std::vector<std::string> inputs = expand_inputs(a->inputs);
    BatchOptions o;
    o.out_dir = a->out_dir;
    o.format = a->format;
    o.jobs = a->jobs;
    o.force = a->force;
    o.base = a->sdf.request();
    if (!a->shard.empty()) {
      const auto [i, n] = parse_shard(a->shard);
      inputs = select_shard(inputs, i, n);
      o.report_name = "batch-report-shard" + std::to_string(i) + "-of-" + std::to_string(n) + ".json";
    }
    if (inputs.empty()) throw InputError("no mesh files found in the inputs");

    const bool tty = isatty(STDERR_FILENO) != 0;
    std::size_t failed_so_far = 0;
    auto progress = [&](std::size_t done, std::size_t total, const AssetOutcome& out) {
      if (out.status == AssetStatus::Failed) ++failed_so_far;
      if (tty) {
        const int width = 30;
        const int filled = static_cast<int>(width * done / std::max<std::size_t>(total, 1));
        std::fprintf(stderr, "\r[%.*s%*s] %zu/%zu assets, %zu failed ", filled, "##############################",
                     width - filled, "", done, total, failed_so_far);
        if (out.status == AssetStatus::Failed) std::fprintf(stderr, "\n  failed: %s\n", out.error.c_str());
        if (done == total) std::fprintf(stderr, "\n");
      } else {
        const char* s = out.status == AssetStatus::Done ? "done" : out.status == AssetStatus::Skipped ? "skipped" : "FAILED";
        std::fprintf(stderr, "sdfkit: [%zu/%zu] %s %s (%.2f s)%s%s\n", done, total, s, out.input.c_str(), out.seconds,
                     out.error.empty() ? "" : ": ", out.error.c_str());
      }
    };
    const BatchSummary s = run_batch(inputs, o, progress);
    std::printf("%zu done, %zu skipped, %zu failed; report: %s\n", s.done, s.skipped, s.failed, s.report.c_str());
    if (s.stale_temporaries > 0)
      std::printf("removed %zu temporary files a killed run had left\n", s.stale_temporaries);
    if (s.done > 0) {
      // Where the time went: the sessions once, then the mean of each stage per asset.
      const BatchTiming& t = s.timing;
      std::printf("%.1f s; %d backend session%s opened once in %.0f ms; per asset (mean ms):", t.wall_ms / 1000.0,
                  t.sessions, t.sessions == 1 ? "" : "s", t.sessions_ms);
      for (const StageTiming& st : t.mean_stages)
        std::printf(" %s%s %.2f%s", st.nested ? "(" : "", st.stage.c_str(), st.milliseconds, st.nested ? ")" : "");
      std::printf("\n");
    }
    if (s.failed > 0) throw sdfkit::Error(std::to_string(s.failed) + " of " + std::to_string(inputs.size()) + " assets failed (see " + s.report + ")");
  });
}

}  // namespace sdfkit::cli

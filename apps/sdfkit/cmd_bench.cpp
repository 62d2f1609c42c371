#include "commands.hpp"

#include "sdfkit/core/error.hpp"

#include <unistd.h>

#include <filesystem>
#include <memory>
#include <vector>

namespace sdfkit::cli {

// `sdfkit bench ...` runs the sdfkit-bench program installed beside this one (it links the
// Embree reference, which the CLI itself does not), passing every argument through.
void add_bench_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("bench", "Benchmark the backends against Embree, CGAL and MeshLab (runs sdfkit-bench; see sdfkit bench --help)");
  cmd->prefix_command();
  cmd->set_help_flag();
  cmd->callback([cmd] {
    char self[4096];
    const ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0) throw Error("cannot locate the sdfkit executable");
    self[n] = 0;
    const std::filesystem::path dir = std::filesystem::path(self).parent_path();
    std::filesystem::path bench;
    for (const auto& candidate : {dir / "sdfkit-bench", dir / "bench" / "sdfkit-bench"})
      if (std::filesystem::exists(candidate)) {
        bench = candidate;
        break;
      }
    if (bench.empty())
      throw Error("sdfkit-bench is not installed next to sdfkit (build with SDFKIT_BUILD_BENCH=ON and SDFKIT_WITH_REFERENCE=ON)");
    std::vector<std::string> args = cmd->remaining();
    std::vector<char*> argv;
    std::string program = bench.string();
    argv.push_back(program.data());
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(program.c_str(), argv.data());
    throw Error("could not run " + program);
  });
}

}  // namespace sdfkit::cli

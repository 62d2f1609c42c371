// sdfkit: the Shape Diameter Function from the command line.
#include "commands.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"
#include "sdfkit/process.hpp"

#include <cstdio>
#include <new>

int main(int argc, char** argv) {
  sdfkit::keep_freed_heap();
  CLI::App app{"sdfkit: the Shape Diameter Function of triangle meshes, on the GPU"};
  app.set_version_flag("--version", std::string("sdfkit ") + SDFKIT_VERSION);
  app.require_subcommand(1);
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "Print informational messages");
  app.parse_complete_callback([&] {
    if (verbose) sdfkit::set_log_level(sdfkit::LogLevel::Info);
  });
  sdfkit::cli::add_info_command(app);
  sdfkit::cli::add_compute_command(app);
  sdfkit::cli::add_devices_command(app);
  sdfkit::cli::add_batch_command(app);
  sdfkit::cli::add_bench_command(app);
  sdfkit::cli::add_skeleton_command(app);
  sdfkit::cli::add_smooth_command(app);
  sdfkit::cli::add_compare_command(app);
  sdfkit::cli::add_pointcloud_skeleton_command(app);
  sdfkit::cli::add_compress_animation_command(app);
#ifdef SDFKIT_CLI_HAS_RENDER
  sdfkit::cli::add_render_command(app);
#endif

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // CLI11 prints the message (or the help / version, which succeed); every usage error is 2.
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const sdfkit::UsageError& e) {
    std::fprintf(stderr, "sdfkit: usage error: %s\n", e.what());
    return 2;
  } catch (const sdfkit::Error& e) {
    std::fprintf(stderr, "sdfkit: error: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "sdfkit: error: out of memory (the input is too large for this machine)\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sdfkit: error: %s\n", e.what());
    return 1;
  }
  return 0;
}

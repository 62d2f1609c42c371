#include "commands.hpp"

#include "sdfkit/core/error.hpp"

#include <cstdio>

namespace sdfkit::cli {

void add_devices_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("devices", "List the Vulkan and OpenCL devices sdfkit can use");
  cmd->callback([] {
    const auto devices = list_all_devices();
    if (devices.empty()) std::printf("no devices found\n");
    for (const DeviceListing& d : devices) {
      std::printf("%-7s %s%s%s\n", d.backend.c_str(), d.description.c_str(),
                  d.usable ? "" : "  [unusable: ", d.usable ? "" : (d.reason + "]").c_str());
    }
    // What --backend auto would run (no backend options given), and why: the rule of
    // sdfkit::choose_backend.
    try {
      const BackendChoice c = choose_backend(BackendConfig{}, SdfOptions{}, devices);
      std::printf("auto    -> %s: %s\n", to_string(c.kind), c.reason.c_str());
    } catch (const Error& e) {
      std::printf("auto    -> none: %s\n", e.what());
    }
  });
}

}  // namespace sdfkit::cli

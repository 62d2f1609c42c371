#pragma once
// Running the real sdfkit executable (or any command) from tests.

#include <filesystem>
#include <string>

namespace sdfkit::test {

struct CommandResult {
  int exit_code = -1;     // -1 when the command did not exit normally
  bool signaled = false;  // killed by a signal (a crash), including shells reporting 128 + n
  std::string out, err;   // captured standard output and error
};

// Runs `command` through the shell, capturing stdout and stderr in files under `scratch`.
CommandResult run_command(const std::string& command, const std::filesystem::path& scratch);

// The whole content of a file ("" when unreadable).
std::string slurp(const std::filesystem::path& path);

}  // namespace sdfkit::test

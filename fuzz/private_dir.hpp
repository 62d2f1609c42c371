#pragma once
// A private directory of this fuzz process under /tmp (mkdtemp with `pattern`, e.g.
// "/tmp/sdfkit-fuzz-XXXXXX"), made on first use and removed when the process exits; a run that
// crashes keeps it. Every harness writes its inputs there, so a run never touches the machine's
// other files.

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace sdfkit::fuzz {

inline const std::string& private_dir(const char* pattern) {
  // Constructed before the exit handler is registered, so destroyed after it runs.
  static std::string dir;
  static const bool made = [pattern] {
    std::vector<char> name(pattern, pattern + std::strlen(pattern) + 1);
    if (mkdtemp(name.data()) == nullptr) std::abort();
    dir = name.data();
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(dir, ignored);
    });
    return true;
  }();
  (void)made;
  return dir;
}

}  // namespace sdfkit::fuzz

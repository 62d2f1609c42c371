#pragma once
// Device tests fail when their device is missing (CI must test every backend for real), unless
// SDFKIT_ALLOW_NO_DEVICE=1 lets them skip, for a developer machine without one.

#include <cstdlib>
#include <string>

namespace sdfkit::test {

inline bool allow_no_device() {
  const char* v = std::getenv("SDFKIT_ALLOW_NO_DEVICE");
  return v != nullptr && std::string(v) == "1";
}

}  // namespace sdfkit::test

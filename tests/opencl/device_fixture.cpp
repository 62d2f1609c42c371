#include "device_fixture.hpp"

#include <cstdlib>
#include <memory>
#include <string>

namespace sdfkit::test {

bool no_device_allowed() {
  const char* v = std::getenv("SDFKIT_ALLOW_NO_DEVICE");
  return v != nullptr && std::string(v) == "1";
}

cl::OpenClBackend* opencl_backend() {
  static std::unique_ptr<cl::OpenClBackend> backend = [] {
    if (cl::list_devices().empty()) return std::unique_ptr<cl::OpenClBackend>();
    return std::make_unique<cl::OpenClBackend>();
  }();
  return backend.get();
}

}  // namespace sdfkit::test

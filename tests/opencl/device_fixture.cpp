#include "device_fixture.hpp"

#include <cstdlib>
#include <memory>
#include <string>

namespace sdfkit::test {

bool no_device_allowed() {
  const char* v = std::getenv("SDFKIT_ALLOW_NO_DEVICE");
  return v != nullptr && std::string(v) == "1";
}

cl::OpenClBackend* opencl_backend(cl::Accel accel) {
  static const bool has_device = !cl::list_devices().empty();
  static std::unique_ptr<cl::OpenClBackend> backends[2];
  if (!has_device) return nullptr;
  auto& b = backends[accel == cl::Accel::Bvh ? 0 : 1];
  if (!b) {
    cl::OpenClConfig config;
    config.accel = accel;
    b = std::make_unique<cl::OpenClBackend>(config);
  }
  return b.get();
}

}  // namespace sdfkit::test

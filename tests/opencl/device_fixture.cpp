#include "device_fixture.hpp"

#include <memory>
#include <string>

namespace sdfkit::test {

const char* tracer_name(Tracer t) {
  switch (t) {
    case Tracer::BvhBundles: return "BvhBundles";
    case Tracer::BvhSingle: return "BvhSingle";
    case Tracer::Octree: return "Octree";
  }
  return "?";
}

cl::OpenClBackend* opencl_backend(Tracer tracer) {
  static const bool has_device = !cl::list_devices().empty();
  static std::unique_ptr<cl::OpenClBackend> backends[3];
  if (!has_device) return nullptr;
  auto& b = backends[static_cast<int>(tracer)];
  if (!b) {
    cl::OpenClConfig config;
    config.accel = tracer == Tracer::Octree ? cl::Accel::Octree : cl::Accel::Bvh;
    config.bvh_bundles = tracer == Tracer::BvhBundles;
    b = std::make_unique<cl::OpenClBackend>(config);
  }
  return b.get();
}

}  // namespace sdfkit::test

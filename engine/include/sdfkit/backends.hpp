#pragma once
// Choosing and creating an SDF backend by name: what the CLI, batch jobs and embedding tools use.
// The Embree reference is not here: it is for tests and benchmarks only.

#include "sdfkit/core/sdf.hpp"

#include <memory>
#include <string>
#include <vector>

namespace sdfkit {

enum class BackendKind { Auto, Vulkan, OpenCL };

// "auto", "vulkan", "opencl" (case-insensitive); throws InputError otherwise.
BackendKind parse_backend_kind(const std::string& name);
const char* to_string(BackendKind kind);

struct BackendConfig {
  BackendKind kind = BackendKind::Auto;  // Auto: the first of auto_order that has a usable device
  // Auto's order. Vulkan first by default (the paper's method; `sdfkit compute`); the skeleton
  // command puts OpenCL first: it calls the SDF at every contraction iteration, where the ray
  // caster's repeated calls are the cheapest (CGAL's hand through lavapipe 1.8 s, PoCL 0.2 s).
  std::vector<BackendKind> auto_order{BackendKind::Vulkan, BackendKind::OpenCL};
  std::string device;                    // device selector (index or name substring); "" = env/auto
  // Vulkan depth peeling
  int views = 0;                         // 0 = the backend's default
  int resolution = 0;                    // 0 = the backend's default
  std::string vulkan_mode;               // "layers" | "lists" (fragment lists); "" = default
  bool validation = false;
  bool profile = false;
  // OpenCL ray casting
  std::size_t memory_cap = 0;            // bytes; 0 = the backend's default
  std::string accel;                     // "bvh" (default) or "octree"
};

// Creates a backend session. Throws DeviceError when the requested backend is not built in or
// has no usable device; with Auto, says why each backend was unavailable.
std::unique_ptr<SdfBackend> make_backend(const BackendConfig& config);

// Which backends this build contains.
std::vector<BackendKind> built_backends();

// One line per device of every built backend, for `sdfkit devices`.
struct DeviceListing {
  std::string backend;  // "vulkan" / "opencl"
  std::string description;
  bool usable = true;
  std::string reason;   // why unusable
};
std::vector<DeviceListing> list_all_devices();

}  // namespace sdfkit

#pragma once
// Choosing and creating an SDF backend by name: what the CLI, batch jobs and embedding tools use.
// The Embree reference is not here: it is for tests and benchmarks only.

#include "sdfkit/core/sdf.hpp"

#include <memory>
#include <span>
#include <string>
#include <vector>

namespace sdfkit {

enum class BackendKind { Auto, Vulkan, OpenCL };

// "auto", "vulkan", "opencl" (case-insensitive); throws InputError otherwise.
BackendKind parse_backend_kind(const std::string& name);
const char* to_string(BackendKind kind);

struct BackendConfig {
  BackendKind kind = BackendKind::Auto;  // Auto: see choose_backend()
  // Auto's preference between backends whose devices are of the same kind (both on a GPU, or
  // both on the CPU with no OpenCL device to prefer). OpenCL first: on the GPU measured (an
  // NVIDIA H200, bench/RESULTS.md "On a GPU") the ray caster was 2.7-6.2x faster than depth
  // peeling from 26k to 416k vertices, 30x at 2.8k, and equal to the reference definition, where
  // depth peeling differs by about 2 % (view sampling); it is also the cheapest for the
  // skeleton's repeated calls. Depth peeling (the paper's method) is what auto picks when only
  // Vulkan has a GPU, and what `--backend vulkan` or {Vulkan, OpenCL} here ask for.
  std::vector<BackendKind> auto_order{BackendKind::OpenCL, BackendKind::Vulkan};
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

// ---- The backend contract ----------------------------------------------------------------
// Every backend honours the SDF's definition (SdfOptions: cone, per vertex or face, false-hit
// rule), the device selector, loading, smoothing and writing. The options below are honoured by
// ONE backend each; setting one (giving it a value other than its default) for the other
// backend is a UsageError naming the backend that uses it, never silently ignored. With
// BackendKind::Auto, the options set narrow the choice to the backend that honours them all.
//  * rays: rays per point of the ray caster (OpenCL). The depth-peeling backend (Vulkan) casts
//    no rays: a point's samples are the cameras inside its cone, about
//    views * (1 - cos(cone / 2)) / 2 of them (--views).
enum class BackendOption { Rays, Views, Resolution, PeelMode, Profile, MemoryCap, Accel };

struct BackendOptionInfo {
  BackendOption option;
  const char* flag;      // the CLI's spelling, "--rays"
  BackendKind used_by;   // the one backend that honours it
  const char* meaning;
};
// The contract, one row per backend-specific option.
std::span<const BackendOptionInfo> backend_option_table();
const BackendOptionInfo& option_info(BackendOption option);
bool honours(BackendKind backend, BackendOption option);

// The backend-specific options that config and sdf set (values other than the defaults of
// BackendConfig{} and SdfOptions{}; SdfOptions::rays at kDefaultRays counts as unset).
std::vector<BackendOption> options_set(const BackendConfig& config, const SdfOptions& sdf);

// Throws UsageError when config or sdf set an option that `backend` would ignore, or that is out
// of range (unknown peel mode or acceleration structure), naming the backend that uses it. The
// one place backend options are validated: make_backend and Session::compute call it.
void check_backend_options(BackendKind backend, const BackendConfig& config, const SdfOptions& sdf);

// ---- Devices and the automatic choice ---------------------------------------------------------

// One line per device of every built backend, for `sdfkit devices`.
struct DeviceListing {
  std::string backend;  // "vulkan" / "opencl"
  std::string description;
  bool usable = true;
  std::string reason;   // why unusable
  std::string name;     // the device's name alone ("llvmpipe (LLVM 15.0.6, 256 bits)")
  int index = 0;        // the backend's own device index (a --device selector)
  bool gpu = false;     // a GPU (discrete, integrated or virtual), not a CPU implementation
};
std::vector<DeviceListing> list_all_devices();

// Which backend runs, and why (one sentence, for run summaries and `sdfkit devices`).
struct BackendChoice {
  BackendKind kind = BackendKind::Auto;
  std::string reason;
};

// The rule of BackendKind::Auto, from a device listing (pure; tested without devices):
//  1. Candidates: the built backends that honour every backend option set (see the contract);
//     options of both backends at once are a UsageError.
//  2. Among candidates with a usable GPU device, the first in config.auto_order: a GPU backend
//     on a real GPU.
//  3. With no GPU: OpenCL when it has a device, even when a Vulkan device exists, since the
//     only Vulkan devices are then CPU rasterizers (lavapipe / llvmpipe, VkPhysicalDeviceType
//     CPU), which are several times slower than ray casting on the same cores at every size
//     measured (armadillo per vertex 0.97 s vs 0.15 s, a 3.3M-triangle mesh 600 s vs 25 s).
//  4. Else the candidate that has any usable device; none: DeviceError saying why.
// With a device selector (config.device), only the listed devices it matches count.
// A kind other than Auto is returned as is ("requested").
BackendChoice choose_backend(const BackendConfig& config, const SdfOptions& sdf,
                             std::span<const DeviceListing> devices);

// Creates a backend session: checks the contract, resolves Auto (choose_backend on
// list_all_devices(); when the chosen backend then fails to open, the next candidate), and says
// what was chosen and why in `choice` when given. Throws UsageError for options the backend
// would ignore, DeviceError when the requested backend is not built in or has no usable device.
std::unique_ptr<SdfBackend> make_backend(const BackendConfig& config, const SdfOptions& sdf = {},
                                         BackendChoice* choice = nullptr);

// Which backends this build contains.
std::vector<BackendKind> built_backends();

}  // namespace sdfkit

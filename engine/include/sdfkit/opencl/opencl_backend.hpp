#pragma once
// The OpenCL ray-casting backend (Shapira et al. 2008, section 3.2): an octree over the
// triangles built on the host, rays generated, traced and gathered on the device, one float and
// one kept-ray count per point read back.
//
// Acceleration structure (OpenClConfig::accel): a BVH (binned SAH, the default: on PoCL it
// needs far fewer triangle tests per ray than the octree) or the paper's octree (front-to-back
// traversal in the style of Laine & Karras). Both are rebuilt on the host by update_positions.
//
// A backend object is a session: it holds the OpenCL context, the compiled program, its kernels
// and the uploaded geometry, so a caller that moves vertices (update_positions) and computes
// again pays only the rebuild of the acceleration structure, the re-upload and the tracing.
// A session is not thread-safe: use one per thread.
//
// Device memory: the geometry (48 bytes per leaf reference of a triangle + 24 bytes per octree
// node) stays resident; the per-point
// buffers (inputs, one 8-byte key per ray, outputs) are sized to fit OpenClConfig::memory_cap,
// and the points are processed in as many batches as that takes.

#include "sdfkit/core/sdf.hpp"
#include "sdfkit/opencl/bvh.hpp"
#include "sdfkit/opencl/octree.hpp"

#include <glm/vec4.hpp>

#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace sdfkit::cl {

struct DeviceInfo {
  std::string platform, name, vendor, version;
  std::string type;  // "GPU", "CPU", "accelerator", "other"
  std::size_t global_memory = 0;  // bytes
  int index = 0;                  // position in list_devices(), usable as a selector
};

// Every OpenCL device of every platform. Empty when no platform is installed (never throws for
// a missing ICD); throws DeviceError for other driver failures.
std::vector<DeviceInfo> list_devices();

enum class Accel { Bvh, Octree };

struct OpenClConfig {
  // "" = the environment variable SDFKIT_CL_DEVICE, or when that is unset or empty the first
  // GPU, else the first device of any kind. Otherwise an index into list_devices() ("0") or a
  // case-insensitive substring of the device name ("nvidia", "pthread").
  std::string device;
  // Bytes of device memory for the per-batch point buffers (not the geometry).
  std::size_t memory_cap = std::size_t{512} << 20;
  Accel accel = Accel::Bvh;
  // Octree: deepest level (root = 0) and the triangle count under which a node stays a leaf.
  int octree_max_depth = 10;
  int octree_leaf_size = 8;
  // BVH: the triangle count under which the SAH may stop splitting, and a node visit's cost in
  // triangle tests; 0 = by tracer: bundles 16 and 3 (a bundle's node visit is two box tests
  // of its lanes and a reduction, about three of its triangle tests: elephant / armadillo /
  // bunny00 at 30 rays 12.1 / 162 / 212 ms with 4 and 1, 10.5 / 150 / 200 ms with 16 and 3,
  // measured with 16-lane bundles), single rays 4 and 1.
  int bvh_leaf_size = 0;
  float bvh_traversal_cost = 0.0f;
  // BVH: update_positions refits the tree (new boxes, same tree: O(n) instead of a build) while
  // its SAH cost stays within this factor of the last full build's; past it, or when a triangle
  // that was degenerate at the build is not any more, it rebuilds. 0 = always rebuild. The
  // skeleton's contraction moves vertices every iteration: measured in engine/opencl/README.md.
  // With bundles, meshes over 2^19 BVH nodes (about a million triangles) always rebuild: the
  // host does not keep their binary tree beside the device's wide copy.
  double bvh_refit_limit = 1.25;
  // BVH: trace ray r of 8 neighbouring points (Morton order) together as one float8 bundle
  // per work item (SIMD on CPU devices: nearly parallel rays from nearby origins, every lane
  // busy) instead of one ray per work item. Unset: bundles on CPU devices, single rays on GPUs
  // (whose work items are scalar lanes already).
  std::optional<bool> bvh_bundles;
  // Work-group size of the trace and gather kernels; 0 = 8 on CPU devices (measured: the
  // driver's choice left a core idle at the end of small launches, and a bundle work item
  // traces several rays, so small groups balance the skeleton's small calls), the driver's on GPUs.
  std::size_t work_group_size = 0;
  // Bundles a trace_bundles work item walks, their traversal steps alternated so that one
  // bundle's next node loads while the others are tested (1, 2 or 4; 0 = 4 on CPU devices,
  // measured in bench/RESULTS.md, 1 on GPUs). Every value gives the same result bit for bit:
  // each bundle visits the same nodes in the same order.
  std::size_t bvh_bundles_per_item = 0;
};

class OpenClBackend final : public SdfBackend {
public:
  // Picks the device, creates the context and queue and compiles the kernels. Throws
  // DeviceError when no platform or no matching device exists or the kernels fail to build
  // (the message holds the build log).
  explicit OpenClBackend(const OpenClConfig& config = {});
  ~OpenClBackend() override;

  std::string name() const override { return "opencl"; }
  std::string device_name() const override;
  void set_mesh(const Mesh& mesh) override;
  void set_shared_mesh(std::shared_ptr<const Mesh> mesh) override;
  void release_mesh() override;
  void update_positions(std::span<const glm::vec3> positions) override;
  RawSdf compute(const SdfQuery& query, const SdfOptions& options) override;
  // "octree_build" (or "bvh_build", "bvh_refit") and "upload" of the last set_mesh/update_positions,
  // "trace_gather" of the last compute (milliseconds, wall clock, including the queue's
  // completion).
  std::vector<StageTiming> last_timings() const override;
  // Geometry + octree + the per-batch buffers of the last compute, in bytes.
  std::size_t device_memory_bytes() const override;

  const DeviceInfo& device() const;
  const Octree& octree() const;  // empty unless accel == Octree
  // Empty unless accel == Bvh. Single rays: the nodes live on the device only; this reads them
  // back. Bundles: the device holds a 4-wide copy, and the nodes are kept on the host for meshes
  // of up to 2^19 nodes (about a million triangles); larger meshes: nodes empty.
  const Bvh& bvh() const;
  // Points per batch the memory cap allows for `rays` rays per point.
  std::size_t batch_points(int rays) const;

  // Test entry points: the device's own versions of the shared definition, run in isolation.
  // Rays: for every normal (outward, unit), the `options.rays` rays of its cone as generated on
  // the device: xyz = world direction, w = the ray's weight; normals.size() * rays entries,
  // point-major.
  std::vector<glm::vec4> ray_directions_for_test(std::span<const glm::vec3> normals,
                                                 const SdfOptions& options);
  // Gather: `lengths` holds rays_per_point entries per point (negative or NaN = no accepted
  // hit), `weights` one weight per ray index; returns the device gather's value and kept count.
  RawSdf gather_lengths_for_test(std::span<const float> lengths, std::span<const float> weights,
                                 int rays_per_point);
  // The shared definition's false-hit rules and cone test (sdf_definition_shared.h) as the
  // device evaluates them. `cases` holds three entries per case: the start point's outward
  // normal (xyz) with the cosine of the cone's half-angle in w, the ray direction, the hit's
  // outward normal. Per case: bit 0 = the Paper rule keeps the hit, bit 1 = the Cgal rule keeps
  // it, bit 2 = the direction lies in the cone around the inward normal.
  std::vector<std::uint32_t> definition_probe_for_test(std::span<const glm::vec4> cases);

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sdfkit::cl

#pragma once
// The reference SDF backend: the shared definition (sdfkit/core/sdf_definition.hpp) evaluated
// with Embree 3 as the ray caster, on the CPU, multi-threaded. Tests and benchmarks hold the
// GPU backends to it; the engine library does not link it.
//
// Per valid query point p with outward normal n: the cone rays of cone_rays() around -n in
// tangent_frame(-n), from p - query.origin_offset * n with tnear = 0; the closest hit is taken,
// its normal is OUR outward face normal of the hit triangle (face_normals(), not Embree's
// geometric normal), accept_hit() drops false hits and gather() makes the value. Degenerate
// triangles (degenerate_faces()) are not in the Embree scene, so they are never hit.
//
// Results are deterministic: the same mesh, query and options give bit-identical values for
// any thread count (each point is traced and gathered by one thread, in a fixed ray order).

#include "sdfkit/core/sdf.hpp"

#include <memory>
#include <span>
#include <string>
#include <vector>

namespace sdfkit::reference {

struct EmbreeOptions {
  // Threads that trace and gather in compute(); 0 = std::thread::hardware_concurrency().
  unsigned threads = 0;
  // Rays handed to Embree per call: 1 (rtcIntersect1), 4, 8 or 16 (rtcIntersect4/8/16 packets
  // of one point's rays). Values differ from one packet size to another only by rounding in
  // Embree's intersectors; for a fixed packet size they are deterministic.
  int packet_size = 8;
};

class EmbreeBackend final : public SdfBackend {
public:
  // Creates the Embree device. Throws DeviceError when Embree cannot start (unsupported CPU)
  // and InputError for options out of range.
  explicit EmbreeBackend(EmbreeOptions options = {});
  ~EmbreeBackend() override;

  std::string name() const override;         // "embree"
  std::string device_name() const override;  // "Embree 3.13.5 (CPU, 8 threads)"

  // Validates the mesh (InputError), then builds the Embree scene from its non-degenerate
  // triangles. Stage "bvh_build".
  void set_mesh(const Mesh& mesh) override;
  // Moves the vertices (same count; Error otherwise) and refits the BVH. When the set of
  // degenerate triangles changes the scene is rebuilt instead. Stage "bvh_build".
  void update_positions(std::span<const glm::vec3> positions) override;
  // Traces the query against the current mesh. Throws Error when no mesh was set, InputError
  // for a malformed query or options. Stage "trace_gather".
  RawSdf compute(const SdfQuery& query, const SdfOptions& options) override;

  std::vector<StageTiming> last_timings() const override;
  // Peak bytes Embree held (BVH and buffers) during the last compute().
  std::size_t device_memory_bytes() const override;

  // Threads compute() uses.
  unsigned thread_count() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sdfkit::reference

#pragma once
// sdfkit.Session: one backend session (device context, compiled programs, uploaded geometry)
// kept between calls, plus the mesh it was given (needed to build queries and fill gaps).
// Every call takes the session's lock, so Python threads may share a session safely; callers
// release the GIL before calling in.

#include "sdfkit/backends.hpp"
#include "sdfkit/core/mesh.hpp"
#include "sdfkit/core/sdf.hpp"

#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace sdfkit::python {

class Session {
public:
  // Opens the backend (throws DeviceError when none is usable).
  explicit Session(const BackendConfig& config);

  std::string name() const { return backend_->name(); }
  std::string device() const { return backend_->device_name(); }

  // Replaces the geometry. `mesh` must have passed validate_mesh.
  void set_mesh(Mesh mesh);
  // Moves the vertices of the current mesh: same count; throws InputError otherwise or for a
  // non-finite coordinate.
  void update_positions(std::vector<glm::vec3> positions);
  // The finished (filled) field on the current mesh; throws InputError without a mesh.
  SdfField compute(const SdfOptions& options);

  // Runs `job` on the backend with the lock held. The job may replace the backend's geometry
  // (run_compute calls set_mesh), so the session forgets its mesh afterwards.
  template <class Job>
  auto with_backend_replacing_mesh(Job&& job) {
    const std::lock_guard lock(mutex_);
    forget_mesh();
    return job(*backend_);
  }

  // Stage timings (ms) of the last call: the backend's own stages plus "total", the wall time
  // of the whole call.
  std::vector<StageTiming> last_timings() const;
  // Kept rays per point of the last compute() (0 where the value was filled).
  std::vector<std::uint32_t> last_kept_rays() const;
  std::size_t vertex_count() const;
  std::size_t face_count() const;

private:
  void forget_mesh();

  mutable std::mutex mutex_;
  std::unique_ptr<SdfBackend> backend_;
  Mesh mesh_;
  bool has_mesh_ = false;
  std::vector<StageTiming> timings_;
  std::vector<std::uint32_t> kept_rays_;
};

}  // namespace sdfkit::python

#pragma once
// sdfkit.Session: the engine's sdfkit::Session (backend session and the mesh it holds) behind a
// lock, so Python threads may share a session safely; callers release the GIL before calling in.

#include "sdfkit/session.hpp"

#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace sdfkit::python {

class Session {
public:
  // Opens the backend (make_backend: the contract and the automatic choice; throws UsageError
  // for options the backend would ignore, DeviceError when none is usable).
  explicit Session(const BackendConfig& config);

  std::string name() const { return session_.backend().name(); }
  std::string device() const { return session_.backend().device_name(); }
  std::string choice() const { return session_.choice().reason; }

  // Replaces the geometry. `mesh` must have passed validate_mesh.
  void set_mesh(Mesh mesh);
  // Moves the vertices of the current mesh: same count; throws InputError otherwise or for a
  // non-finite coordinate.
  void update_positions(std::vector<glm::vec3> positions);
  // The finished (filled) field on the current mesh; throws InputError without a mesh,
  // UsageError for options the backend would ignore.
  SdfField compute(const SdfOptions& options);

  // Runs `job` on the engine session with the lock held (run_compute replaces its mesh).
  template <class Job>
  auto with_session(Job&& job) {
    const std::lock_guard lock(mutex_);
    kept_rays_.clear();
    return job(session_);
  }

  // Stage timings (ms) of the last call: the backend's own stages plus "total", the wall time
  // of the whole call.
  std::vector<StageTiming> last_timings() const;
  // Kept rays per point of the last compute() (0 where the value was filled).
  std::vector<std::uint32_t> last_kept_rays() const;
  std::size_t vertex_count() const;
  std::size_t face_count() const;

private:
  mutable std::mutex mutex_;
  sdfkit::Session session_;
  std::vector<StageTiming> timings_;
  std::vector<std::uint32_t> kept_rays_;
};

}  // namespace sdfkit::python

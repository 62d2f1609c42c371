#pragma once
// sdfkit::Session: a backend session (device context, compiled programs, uploaded geometry) and
// the mesh it holds, kept between calls. compute() measures the session's own mesh: the query
// and the gap filling use the geometry the backend was given, never a mesh handed in again.
// What `sdfkit compute`, `batch`, `render`, `skeleton` and the Python module use.

#include "sdfkit/backends.hpp"
#include "sdfkit/core/sdf.hpp"

#include <memory>
#include <span>
#include <string>
#include <vector>

namespace sdfkit {

class Session {
public:
  // Opens the backend `config` names; with Auto the one choose_backend picks for options like
  // `sdf` (the options the session will compute with; see the backend contract in backends.hpp).
  // Throws UsageError for options the backend would ignore, DeviceError without a device.
  explicit Session(const BackendConfig& config, const SdfOptions& sdf = {});
  // Wraps a backend made elsewhere (a test's, the Embree reference, an embedding tool's own).
  explicit Session(std::unique_ptr<SdfBackend> backend);
  ~Session();
  Session(Session&&) noexcept;
  Session& operator=(Session&&) noexcept;

  SdfBackend& backend() { return *backend_; }
  const SdfBackend& backend() const { return *backend_; }
  // Which backend runs and why ("requested", "opencl on ...: no GPU, ...").
  const BackendChoice& choice() const { return choice_; }

  // Uploads `mesh` (which must have passed validate_mesh) and keeps it: moved in, the one copy
  // is shared with the backend (set_shared_mesh), not copied again.
  void set_mesh(Mesh mesh);
  // Moves the vertices of the session's mesh (same count; InputError otherwise, or for a
  // non-finite coordinate). After a backend failure the session holds no mesh.
  void update_positions(std::span<const glm::vec3> positions);
  bool has_mesh() const { return has_mesh_; }
  const Mesh& mesh() const { return *mesh_; }

  // The finished (filled) field of the session's mesh. Throws InputError without a mesh and
  // UsageError when `options` set what this backend would ignore (--rays on Vulkan).
  SdfField compute(const SdfOptions& options);

private:
  BackendChoice choice_;  // before backend_: the constructor's make_backend fills it
  std::unique_ptr<SdfBackend> backend_;
  // The session's mesh; the backend holds a const view of the same object (set_shared_mesh).
  std::shared_ptr<Mesh> mesh_ = std::make_shared<Mesh>();
  bool has_mesh_ = false;
};

// The kind of a backend by its name() ("vulkan", "opencl"); Auto for any other backend (the
// Embree reference, an embedding tool's own), which is taken to honour every option.
BackendKind kind_of(const SdfBackend& backend);

}  // namespace sdfkit

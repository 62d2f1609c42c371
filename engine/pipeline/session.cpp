#include "sdfkit/session.hpp"

#include "sdfkit/core/error.hpp"

#include <cmath>

namespace sdfkit {

BackendKind kind_of(const SdfBackend& backend) {
  const std::string name = backend.name();
  if (name == to_string(BackendKind::Vulkan)) return BackendKind::Vulkan;
  if (name == to_string(BackendKind::OpenCL)) return BackendKind::OpenCL;
  return BackendKind::Auto;
}

Session::Session(const BackendConfig& config, const SdfOptions& sdf) : backend_(make_backend(config, sdf, &choice_)) {}

Session::Session(std::unique_ptr<SdfBackend> backend) : choice_{BackendKind::Auto, "given"}, backend_(std::move(backend)) {
  if (!backend_) throw Error("Session: no backend");
  choice_.kind = kind_of(*backend_);
}

Session::~Session() = default;
Session::Session(Session&&) noexcept = default;
Session& Session::operator=(Session&&) noexcept = default;

void Session::set_mesh(Mesh mesh) {
  has_mesh_ = false;
  backend_->release_mesh();
  mesh_ = std::make_shared<Mesh>(std::move(mesh));
  backend_->set_shared_mesh(mesh_);
  has_mesh_ = true;
}

void Session::update_positions(std::span<const glm::vec3> positions) {
  if (!has_mesh_) throw InputError("update_positions: the session has no mesh; call set_mesh first");
  if (positions.size() != mesh_->positions.size())
    throw InputError("update_positions: got " + std::to_string(positions.size()) + " vertices, the mesh has " +
                     std::to_string(mesh_->positions.size()) + " (use set_mesh to change the mesh)");
  for (std::size_t v = 0; v < positions.size(); ++v)
    if (!std::isfinite(positions[v].x) || !std::isfinite(positions[v].y) || !std::isfinite(positions[v].z))
      throw InputError("update_positions: vertex " + std::to_string(v) + " has a non-finite coordinate (NaN or Inf)");
  try {
    backend_->update_positions(positions);
  } catch (...) {
    has_mesh_ = false;  // the backend's geometry is in an unknown state
    backend_->release_mesh();
    mesh_ = std::make_shared<Mesh>();
    throw;
  }
  mesh_->positions.assign(positions.begin(), positions.end());
}

SdfField Session::compute(const SdfOptions& options) {
  if (!has_mesh_) throw InputError("compute: the session has no mesh; call set_mesh first");
  if (choice_.kind != BackendKind::Auto) check_backend_options(choice_.kind, BackendConfig{}, options);
  return compute_sdf(*backend_, *mesh_, options);
}

}  // namespace sdfkit

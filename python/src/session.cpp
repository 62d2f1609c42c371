#include "session.hpp"

#include "sdfkit/core/error.hpp"

#include <chrono>
#include <cmath>

namespace sdfkit::python {
namespace {

double elapsed_ms(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

Session::Session(const BackendConfig& config) : backend_(make_backend(config)) {}

void Session::set_mesh(Mesh mesh) {
  const std::lock_guard lock(mutex_);
  const auto start = std::chrono::steady_clock::now();
  forget_mesh();
  backend_->set_mesh(mesh);
  mesh_ = std::move(mesh);
  has_mesh_ = true;
  timings_ = backend_->last_timings();
  timings_.push_back({"total", elapsed_ms(start)});
}

void Session::update_positions(std::vector<glm::vec3> positions) {
  const std::lock_guard lock(mutex_);
  if (!has_mesh_) throw InputError("update_positions: the session has no mesh; call set_mesh first");
  if (positions.size() != mesh_.positions.size())
    throw InputError("update_positions: got " + std::to_string(positions.size()) + " vertices, the mesh has " +
                     std::to_string(mesh_.positions.size()) + " (use set_mesh to change the mesh)");
  for (std::size_t v = 0; v < positions.size(); ++v)
    if (!std::isfinite(positions[v].x) || !std::isfinite(positions[v].y) || !std::isfinite(positions[v].z))
      throw InputError("update_positions: vertex " + std::to_string(v) + " has a non-finite coordinate (NaN or Inf)");
  const auto start = std::chrono::steady_clock::now();
  try {
    backend_->update_positions(positions);
  } catch (...) {
    forget_mesh();  // the backend's geometry is in an unknown state
    throw;
  }
  mesh_.positions = std::move(positions);
  timings_ = backend_->last_timings();
  timings_.push_back({"total", elapsed_ms(start)});
}

SdfField Session::compute(const SdfOptions& options) {
  const std::lock_guard lock(mutex_);
  if (!has_mesh_) throw InputError("compute: the session has no mesh; call set_mesh first");
  const auto start = std::chrono::steady_clock::now();
  SdfField field = compute_sdf(*backend_, mesh_, options);
  timings_ = backend_->last_timings();
  timings_.push_back({"total", elapsed_ms(start)});
  kept_rays_ = field.kept_rays;
  return field;
}

std::vector<StageTiming> Session::last_timings() const {
  const std::lock_guard lock(mutex_);
  return timings_;
}

std::vector<std::uint32_t> Session::last_kept_rays() const {
  const std::lock_guard lock(mutex_);
  return kept_rays_;
}

std::size_t Session::vertex_count() const {
  const std::lock_guard lock(mutex_);
  return mesh_.positions.size();
}

std::size_t Session::face_count() const {
  const std::lock_guard lock(mutex_);
  return mesh_.triangles.size();
}

void Session::forget_mesh() {
  mesh_ = Mesh{};
  has_mesh_ = false;
  kept_rays_.clear();
}

}  // namespace sdfkit::python

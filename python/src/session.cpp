#include "session.hpp"

#include <chrono>

namespace sdfkit::python {
namespace {

double elapsed_ms(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

Session::Session(const BackendConfig& config) : session_(config) {}

void Session::set_mesh(Mesh mesh) {
  const std::lock_guard lock(mutex_);
  const auto start = std::chrono::steady_clock::now();
  kept_rays_.clear();
  session_.set_mesh(std::move(mesh));
  timings_ = session_.backend().last_timings();
  timings_.push_back({"total", elapsed_ms(start)});
}

void Session::update_positions(std::vector<glm::vec3> positions) {
  const std::lock_guard lock(mutex_);
  const auto start = std::chrono::steady_clock::now();
  kept_rays_.clear();
  session_.update_positions(positions);
  timings_ = session_.backend().last_timings();
  timings_.push_back({"total", elapsed_ms(start)});
}

SdfField Session::compute(const SdfOptions& options) {
  const std::lock_guard lock(mutex_);
  const auto start = std::chrono::steady_clock::now();
  SdfField field = session_.compute(options);
  timings_ = session_.backend().last_timings();
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
  return session_.has_mesh() ? session_.mesh().positions.size() : 0;
}

std::size_t Session::face_count() const {
  const std::lock_guard lock(mutex_);
  return session_.has_mesh() ? session_.mesh().triangles.size() : 0;
}

}  // namespace sdfkit::python

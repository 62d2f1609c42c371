// Cameras: spherical Fibonacci view directions with orthonormal image frames (the frame of the
// shared definition, tangent_frame).
#include "session.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/sdf_definition.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace sdfkit::vk {

// Point i of n of the spherical Fibonacci set on the whole unit sphere (cameras, normal groups).
glm::dvec3 fibonacci_sphere_point(int i, int n) {
  const double z = 1.0 - (2.0 * i + 1.0) / n;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = std::fmod(i * kGoldenAngle, 2.0 * M_PI);
  return {r * std::cos(phi), r * std::sin(phi), z};
}

std::vector<GpuCamera> make_cameras(int n) {
  std::vector<GpuCamera> cams(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const Frame f = tangent_frame(glm::normalize(glm::vec3(fibonacci_sphere_point(i, n))));
    cams[static_cast<std::size_t>(i)] = {glm::vec4(f.t, 0.0f), glm::vec4(f.b, 0.0f), glm::vec4(f.axis, 0.0f)};
  }
  return cams;
}

}  // namespace sdfkit::vk

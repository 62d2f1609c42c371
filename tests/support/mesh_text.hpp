#pragma once
// A mesh as the text of an OFF file (positions to 9 significant digits, float-exact), for tests
// that load a mesh they built through the file loaders.

#include "sdfkit/core/mesh.hpp"

#include <sstream>
#include <string>

namespace sdfkit::test {

inline std::string off_text(const Mesh& m) {
  std::ostringstream o;
  o.precision(9);
  o << "OFF\n" << m.positions.size() << ' ' << m.triangles.size() << " 0\n";
  for (const glm::vec3& p : m.positions) o << p.x << ' ' << p.y << ' ' << p.z << '\n';
  for (const Triangle& t : m.triangles) o << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  return o.str();
}

}  // namespace sdfkit::test

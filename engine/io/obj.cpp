// OBJ reader: `v x y z [w] [r g b]` and `f` lines whose corners are `v`, `v/vt`, `v//vn` or
// `v/vt/vn` (1-based; negative = relative to the vertices read so far), polygons
// fan-triangulated. Every other statement (vt, vn, g, o, s, usemtl, mtllib, ...) is ignored;
// line and point elements are counted in a warning.

#include "readers.hpp"
#include "text_cursor.hpp"

#include <vector>

namespace sdfkit::io::detail {

RawMesh read_obj(const std::string& path, std::string_view data) {
  TextCursor c(data, path);
  RawMesh out;
  std::vector<std::int64_t> face_vertices;  // per triangle corner, 0-based, unchecked
  std::vector<std::int64_t> corner_raw;
  std::size_t lines_skipped = 0, points_skipped = 0, faces_skipped = 0;

  while (!c.at_end()) {
    if (c.at_line_end()) {
      c.next_line();
      continue;
    }
    const std::string_view key = c.word();
    if (key == "v") {
      glm::vec3 p;
      for (int k = 0; k < 3; ++k) {
        if (!c.try_float(p[k]))
          c.expected("coordinate " + std::to_string(k + 1) + " of vertex " +
                     std::to_string(out.positions.size() + 1));
      }
      out.positions.push_back(p);
    } else if (key == "f") {
      corner_raw.clear();
      const auto count = static_cast<std::int64_t>(out.positions.size());
      while (!c.at_line_end()) {
        std::int64_t index = 0;
        if (!c.try_int(index, /*allow_slash=*/true))
          c.expected("a face corner (v, v/vt, v//vn or v/vt/vn)");
        if (index == 0) c.error("vertex index 0 in a face (OBJ indices start at 1)");
        const std::int64_t resolved = index > 0 ? index - 1 : count + index;
        if (resolved < 0)
          c.error("relative vertex index " + std::to_string(index) +
                  " points before the first vertex");
        corner_raw.push_back(resolved);
        c.skip_token();  // "/vt/vn"
      }
      if (corner_raw.size() < 3) {
        ++faces_skipped;
      } else {
        for (std::size_t k = 1; k + 1 < corner_raw.size(); ++k) {
          face_vertices.push_back(corner_raw[0]);
          face_vertices.push_back(corner_raw[k]);
          face_vertices.push_back(corner_raw[k + 1]);
        }
      }
    } else if (key == "l") {
      ++lines_skipped;
    } else if (key == "p") {
      ++points_skipped;
    }
    c.next_line();
  }

  // Checked at the end: a face may name a vertex defined further down.
  const auto nv = static_cast<std::int64_t>(out.positions.size());
  out.triangles.resize(face_vertices.size() / 3);
  for (std::size_t i = 0; i < face_vertices.size(); ++i) {
    if (face_vertices[i] >= nv)
      fail(path, "triangle " + std::to_string(i / 3) + " uses vertex " +
                     std::to_string(face_vertices[i] + 1) + " but the file has " +
                     std::to_string(nv) + " vertices");
    out.triangles[i / 3][i % 3] = static_cast<std::uint32_t>(face_vertices[i]);
  }
  if (lines_skipped > 0)
    out.warnings.push_back("skipped " + std::to_string(lines_skipped) + " line elements (l)");
  if (points_skipped > 0)
    out.warnings.push_back("skipped " + std::to_string(points_skipped) + " point elements (p)");
  if (faces_skipped > 0)
    out.warnings.push_back("skipped " + std::to_string(faces_skipped) +
                           " faces with fewer than 3 vertices");
  return out;
}

}  // namespace sdfkit::io::detail

// OFF reader: "[ST][C][N]OFF" header (the keyword may be missing), counts, vertex lines whose
// extra columns (normals, colours, texture coordinates) are ignored, polygon lines (extra
// columns = colours, ignored) fan-triangulated, '#' comments anywhere.

#include "readers.hpp"
#include "text_cursor.hpp"

#include <algorithm>
#include <vector>

namespace sdfkit::io::detail {
namespace {

// Reads the keyword; false when the file starts directly with the counts.
bool read_keyword(TextCursor& c, const std::string& path) {
  const std::string_view head = c.peek_word();
  if (head.size() < 3 || head.substr(head.size() - 3) != "OFF") {
    std::int64_t probe = 0;
    if (c.try_int(probe)) return false;  // counts without a keyword: accepted
    fail(path, "not an OFF file (it does not start with 'OFF')");
  }
  const std::string_view prefix = head.substr(0, head.size() - 3);
  for (const char ch : prefix) {
    if (ch == '4' || ch == 'n')
      fail(path, "unsupported OFF variant '" + std::string(head) + "' (only 3D OFF is read)");
    if (ch != 'S' && ch != 'T' && ch != 'C' && ch != 'N')
      fail(path, "not an OFF file (unknown keyword '" + TextCursor::printable(head) + "')");
  }
  c.word();
  return true;
}

std::int64_t read_count(TextCursor& c, const char* what) {
  c.skip_blank();
  std::int64_t n = 0;
  if (!c.try_int(n)) c.expected(what);
  if (n < 0) c.error(std::string("negative ") + what);
  return n;
}

}  // namespace

RawMesh read_off(const std::string& path, std::string_view data) {
  TextCursor c(data, path);
  c.skip_blank();
  if (c.at_end()) fail(path, "the file is empty");
  read_keyword(c, path);
  const std::int64_t nv = read_count(c, "the vertex count");
  const std::int64_t nf = read_count(c, "the face count");
  c.next_line();  // the edge count, if any, is ignored

  // A vertex line takes at least 6 bytes ("0 0 0\n"), a face line at least 2 ("0\n"): a header
  // that claims more than the file can hold is an error, not an allocation.
  const auto bytes = static_cast<double>(c.remaining()) + 1.0;
  if (6.0 * static_cast<double>(nv) + 2.0 * static_cast<double>(nf) > bytes)
    fail(path, "the header declares " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                   " faces, more than the file's " + std::to_string(data.size()) +
                   " bytes can hold (truncated file?)");
  if (nv > static_cast<std::int64_t>(UINT32_MAX)) fail(path, "too many vertices");
  check_vertex_count(path, static_cast<std::uint64_t>(nv));            // LoadOptions limits
  check_triangle_count(path, static_cast<std::uint64_t>(nf), "faces");

  RawMesh out;
  out.positions.resize(static_cast<std::size_t>(nv));
  for (std::int64_t v = 0; v < nv; ++v) {
    c.skip_blank();
    glm::vec3& p = out.positions[static_cast<std::size_t>(v)];
    for (int k = 0; k < 3; ++k) {
      if (!c.try_float(p[k]))
        c.expected("coordinate " + std::to_string(k + 1) + " of vertex " + std::to_string(v));
    }
    c.next_line();
  }

  // Most faces are triangles ("3 a b c\n" >= 8 bytes): reserve only what the file can hold.
  out.triangles.reserve(static_cast<std::size_t>(
      std::min<std::int64_t>(nf, static_cast<std::int64_t>(c.remaining() / 8 + 1))));
  std::vector<std::uint32_t> corners;
  std::size_t skipped = 0;
  for (std::int64_t f = 0; f < nf; ++f) {
    c.skip_blank();
    std::int64_t n = 0;
    if (!c.try_int(n)) c.expected("the corner count of face " + std::to_string(f));
    if (n < 0 || static_cast<std::size_t>(n) > c.remaining() / 2 + 1)
      c.error("face " + std::to_string(f) + " has an impossible corner count " + std::to_string(n));
    corners.resize(static_cast<std::size_t>(n));
    for (std::int64_t k = 0; k < n; ++k) {
      std::int64_t index = 0;
      if (!c.try_int(index))
        c.expected("vertex index " + std::to_string(k + 1) + " of face " + std::to_string(f));
      if (index < 0 || index >= nv)
        c.error("face " + std::to_string(f) + " uses vertex " + std::to_string(index) +
                " but the file has " + std::to_string(nv) + " vertices");
      corners[static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(index);
    }
    if (n < 3) ++skipped;
    append_fan(out.triangles, corners.data(), corners.size());
    c.next_line();
  }
  if (skipped > 0)
    out.warnings.push_back("skipped " + std::to_string(skipped) +
                           " faces with fewer than 3 vertices");
  return out;
}

}  // namespace sdfkit::io::detail

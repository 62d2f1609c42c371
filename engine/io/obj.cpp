// OBJ reader: `v x y z [w] [r g b]` and `f` lines whose corners are `v`, `v/vt`, `v//vn` or
// `v/vt/vn` (1-based; negative = relative to the vertices read so far), polygons
// fan-triangulated. Every other statement (vt, vn, g, o, s, usemtl, mtllib, ...) is ignored;
// line and point elements are counted in a warning.
//
// Parsed in parallel: the file is cut at line breaks into one chunk per thread; a first pass
// counts each chunk's vertices and triangles (so the arrays are allocated once, at their final
// size, after a memory check), a second parses every chunk into its own range of them. Errors
// are those of the earliest chunk, as a sequential reader would report them.

#include "readers.hpp"
#include "text_cursor.hpp"

#include "sdfkit/core/parallel.hpp"

#include <exception>
#include <thread>
#include <vector>

namespace sdfkit::io::detail {
namespace {

struct Chunk {
  std::size_t begin = 0, end = 0;  // byte range, whole lines
  std::size_t vertices = 0, triangles = 0;
  std::size_t vertex_offset = 0, triangle_offset = 0;  // where its output goes
  std::size_t lines_skipped = 0, points_skipped = 0, faces_skipped = 0;
  std::exception_ptr error;
};

bool is_blank(char ch) { return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\f' || ch == '\v'; }

// First pass over one chunk: statements counted without parsing numbers (a face's corners are
// its whitespace-separated tokens before a '#').
void count_chunk(std::string_view data, Chunk& c) {
  std::size_t p = c.begin;
  while (p < c.end) {
    while (p < c.end && is_blank(data[p])) ++p;
    std::size_t eol = data.find('\n', p);
    if (eol == std::string_view::npos || eol > c.end) eol = c.end;
    if (p + 1 < eol && is_blank(data[p + 1])) {
      if (data[p] == 'v') {
        ++c.vertices;
      } else if (data[p] == 'f') {
        std::size_t corners = 0;
        for (std::size_t q = p + 1; q < eol && data[q] != '#';) {
          while (q < eol && is_blank(data[q])) ++q;
          if (q >= eol || data[q] == '#') break;
          ++corners;
          while (q < eol && !is_blank(data[q])) ++q;
        }
        if (corners >= 3) c.triangles += corners - 2;
      }
    }
    p = eol + 1;
  }
}

// Second pass: parses the chunk into positions / triangle corners (0-based, unchecked against
// the vertex count: a face may name a vertex defined further down).
void parse_chunk(const std::string& path, std::string_view data, Chunk& c, std::vector<glm::vec3>& positions,
                 std::vector<Triangle>& triangles) {
  TextCursor cur(data.substr(0, c.end), path, c.begin);
  std::size_t v_out = c.vertex_offset, t_out = c.triangle_offset;
  std::int64_t corner_raw[3];
  while (!cur.at_end()) {
    if (cur.at_line_end()) {
      cur.next_line();
      continue;
    }
    const std::string_view key = cur.word();
    if (key == "v") {
      glm::vec3 p;
      for (int k = 0; k < 3; ++k) {
        if (!cur.try_float(p[k]))
          cur.expected("coordinate " + std::to_string(k + 1) + " of vertex " + std::to_string(v_out + 1));
      }
      if (v_out >= c.vertex_offset + c.vertices) cur.error("a vertex the first pass did not count");
      positions[v_out++] = p;
    } else if (key == "f") {
      const auto count = static_cast<std::int64_t>(v_out);  // vertices read so far
      std::size_t n = 0;
      while (!cur.at_line_end()) {
        std::int64_t index = 0;
        if (!cur.try_int(index, /*allow_slash=*/true)) cur.expected("a face corner (v, v/vt, v//vn or v/vt/vn)");
        if (index == 0) cur.error("vertex index 0 in a face (OBJ indices start at 1)");
        const std::int64_t resolved = index > 0 ? index - 1 : count + index;
        if (resolved < 0)
          cur.error("relative vertex index " + std::to_string(index) + " points before the first vertex");
        if (resolved > static_cast<std::int64_t>(UINT32_MAX) - 1)
          cur.error("vertex index " + std::to_string(index) + " is out of range");
        cur.skip_token();  // "/vt/vn"
        // Fan: corner 0 stays, each new corner closes a triangle with the previous one.
        if (n < 3) {
          corner_raw[n] = resolved;
        } else {
          corner_raw[1] = corner_raw[2];
          corner_raw[2] = resolved;
        }
        ++n;
        if (n >= 3 && t_out >= c.triangle_offset + c.triangles) cur.error("a face the first pass did not count");
        if (n >= 3)
          triangles[t_out++] = Triangle{static_cast<std::uint32_t>(corner_raw[0]),
                                        static_cast<std::uint32_t>(corner_raw[1]),
                                        static_cast<std::uint32_t>(corner_raw[2])};
      }
      if (n < 3) ++c.faces_skipped;
    } else if (key == "l") {
      ++c.lines_skipped;
    } else if (key == "p") {
      ++c.points_skipped;
    }
    cur.next_line();
  }
}

}  // namespace

RawMesh read_obj(const std::string& path, std::string_view data) {
  // Chunks of at least 4 MiB, cut after a line break.
  const std::size_t threads = hardware_threads();
  const std::size_t parts = std::max<std::size_t>(1, std::min(threads, data.size() / (std::size_t{4} << 20)));
  std::vector<Chunk> chunks;
  std::size_t begin = 0;
  for (std::size_t k = 1; k <= parts && begin < data.size(); ++k) {
    std::size_t end = k == parts ? data.size() : data.size() * k / parts;
    if (end < data.size()) {
      const std::size_t nl = data.find('\n', std::max(end, begin));
      end = nl == std::string_view::npos ? data.size() : nl + 1;
    }
    Chunk c;
    c.begin = begin;
    c.end = end;
    chunks.push_back(c);
    begin = end;
  }
  if (chunks.empty()) chunks.emplace_back();

  parallel_for(chunks.size(), [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) count_chunk(data, chunks[k]);
  }, 1);
  std::size_t nv = 0, nt = 0;
  for (Chunk& c : chunks) {
    c.vertex_offset = nv;
    c.triangle_offset = nt;
    nv += c.vertices;
    nt += c.triangles;
  }
  if (nv > UINT32_MAX) fail(path, "too many vertices");
  check_mesh_fits(path, nv, nt);

  RawMesh out;
  out.positions.resize(nv);
  out.triangles.resize(nt);
  parallel_for(chunks.size(), [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      try {
        parse_chunk(path, data, chunks[k], out.positions, out.triangles);
      } catch (...) {
        chunks[k].error = std::current_exception();
      }
    }
  }, 1);
  std::size_t lines_skipped = 0, points_skipped = 0, faces_skipped = 0;
  for (const Chunk& c : chunks) {
    if (c.error) std::rethrow_exception(c.error);
    lines_skipped += c.lines_skipped;
    points_skipped += c.points_skipped;
    faces_skipped += c.faces_skipped;
  }

  // Checked at the end: a face may name a vertex defined further down.
  for (std::size_t f = 0; f < out.triangles.size(); ++f)
    for (const std::uint32_t v : out.triangles[f])
      if (v >= nv)
        fail(path, "triangle " + std::to_string(f) + " uses vertex " + std::to_string(std::uint64_t{v} + 1) +
                       " but the file has " + std::to_string(nv) + " vertices");
  if (lines_skipped > 0)
    out.warnings.push_back("skipped " + std::to_string(lines_skipped) + " line elements (l)");
  if (points_skipped > 0)
    out.warnings.push_back("skipped " + std::to_string(points_skipped) + " point elements (p)");
  if (faces_skipped > 0)
    out.warnings.push_back("skipped " + std::to_string(faces_skipped) + " faces with fewer than 3 vertices");
  return out;
}

}  // namespace sdfkit::io::detail

// PLY reader: ascii, binary_little_endian and binary_big_endian. Vertex x, y, z of any numeric
// type; faces from the list property `vertex_indices` (or `vertex_index`) with any count and
// index types, polygons fan-triangulated; a scalar `quality` of vertices or faces is kept (the
// SDF values sdfkit writes); every other element and property is read past.

#include "readers.hpp"
#include "text_cursor.hpp"

#include "sdfkit/core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <optional>
#include <vector>

namespace sdfkit::io::detail {
namespace {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };
enum class PlyEncoding { Ascii, BinaryLittle, BinaryBig };

struct PlyProperty {
  std::string name;
  bool is_list = false;
  PlyType count_type = PlyType::UInt8;  // lists only
  PlyType type = PlyType::Float32;      // the scalar, or the list's items
};

struct PlyElement {
  std::string name;
  std::int64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::Ascii;
  std::vector<PlyElement> elements;
  std::size_t data_start = 0;  // first byte after "end_header\n"
};

std::size_t type_size(PlyType t) {
  switch (t) {
    case PlyType::Int8:
    case PlyType::UInt8: return 1;
    case PlyType::Int16:
    case PlyType::UInt16: return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32: return 4;
    case PlyType::Float64: return 8;
  }
  return 0;
}

bool is_integral(PlyType t) { return t != PlyType::Float32 && t != PlyType::Float64; }

std::optional<PlyType> parse_type(std::string_view s) {
  if (s == "char" || s == "int8") return PlyType::Int8;
  if (s == "uchar" || s == "uint8") return PlyType::UInt8;
  if (s == "short" || s == "int16") return PlyType::Int16;
  if (s == "ushort" || s == "uint16") return PlyType::UInt16;
  if (s == "int" || s == "int32") return PlyType::Int32;
  if (s == "uint" || s == "uint32") return PlyType::UInt32;
  if (s == "float" || s == "float32") return PlyType::Float32;
  if (s == "double" || s == "float64") return PlyType::Float64;
  return std::nullopt;
}

PlyType read_type(TextCursor& c) {
  const std::string_view w = c.word();
  const std::optional<PlyType> t = parse_type(w);
  if (!t) c.error("unknown property type '" + TextCursor::printable(w) + "'");
  return *t;
}

PlyHeader parse_header(const std::string& path, std::string_view data) {
  TextCursor c(data, path);
  if (c.word() != "ply" || !c.at_line_end())
    fail(path, "not a PLY file (it does not start with 'ply')");
  c.next_line();
  PlyHeader h;
  bool have_format = false;
  while (true) {
    if (c.at_end()) fail(path, "the PLY header has no 'end_header' line");
    if (c.at_line_end()) {
      c.next_line();
      continue;
    }
    const std::string_view key = c.word();
    if (key == "format") {
      const std::string_view enc = c.word();
      if (enc == "ascii")
        h.encoding = PlyEncoding::Ascii;
      else if (enc == "binary_little_endian")
        h.encoding = PlyEncoding::BinaryLittle;
      else if (enc == "binary_big_endian")
        h.encoding = PlyEncoding::BinaryBig;
      else
        c.error("unknown PLY format '" + TextCursor::printable(enc) + "'");
      have_format = true;
    } else if (key == "comment" || key == "obj_info") {
      // ignored
    } else if (key == "element") {
      PlyElement e;
      e.name = std::string(c.word());
      if (e.name.empty()) c.error("an element without a name");
      if (!c.try_int(e.count) || e.count < 0) c.expected("the element count of '" + e.name + "'");
      h.elements.push_back(std::move(e));
    } else if (key == "property") {
      if (h.elements.empty()) c.error("a property before any element");
      PlyProperty p;
      if (c.peek_word() == "list") {
        c.word();
        p.is_list = true;
        p.count_type = read_type(c);
        p.type = read_type(c);
      } else {
        p.type = read_type(c);
      }
      p.name = std::string(c.word());
      if (p.name.empty()) c.error("a property without a name");
      h.elements.back().properties.push_back(std::move(p));
    } else if (key == "end_header") {
      c.next_line();
      h.data_start = c.position();
      break;
    } else {
      c.error("unknown PLY header line '" + TextCursor::printable(key) + "'");
    }
    c.next_line();
  }
  if (!have_format) fail(path, "the PLY header has no 'format' line");
  return h;
}

// Smallest number of bytes one row of the element can take in the file.
double min_row_bytes(const PlyElement& e, PlyEncoding enc) {
  double bytes = 0.0;
  for (const PlyProperty& p : e.properties) {
    if (enc == PlyEncoding::Ascii)
      bytes += 2.0;  // one digit and a separator
    else
      bytes += static_cast<double>(type_size(p.is_list ? p.count_type : p.type));
  }
  return bytes;
}

// One element reader for both encodings: `Source` provides scalar(type) (and skip for binary).
struct AsciiSource {
  TextCursor& c;
  const std::string& what;
  double scalar(PlyType t) {
    c.skip_blank(false);
    if (is_integral(t)) {
      std::int64_t v = 0;
      if (!c.try_int(v)) c.expected("an integer in " + what);
      return static_cast<double>(v);
    }
    float v = 0.0f;
    if (!c.try_float(v)) c.expected("a number in " + what);
    return static_cast<double>(v);
  }
  void skip_scalar(PlyType) {
    c.skip_blank(false);
    if (c.word().empty()) c.expected("a value in " + what);
  }
};

template <typename Source>
void read_elements(const std::string& path, const PlyHeader& h, std::int64_t vertex_count,
                   std::size_t data_bytes, Source make_source, RawMesh& out) {
  std::vector<std::uint32_t> corners;
  std::size_t skipped_faces = 0;
  for (const PlyElement& e : h.elements) {
    const bool is_vertex = e.name == "vertex";
    const bool is_face = e.name == "face";
    int xyz[3] = {-1, -1, -1};
    int face_list = -1;
    int quality = -1;
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const PlyProperty& p = e.properties[i];
      if ((is_vertex || is_face) && !p.is_list && p.name == "quality") quality = static_cast<int>(i);
      if (is_vertex && !p.is_list) {
        if (p.name == "x") xyz[0] = static_cast<int>(i);
        if (p.name == "y") xyz[1] = static_cast<int>(i);
        if (p.name == "z") xyz[2] = static_cast<int>(i);
      }
      if (is_face && p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index"))
        face_list = static_cast<int>(i);
    }
    if (is_vertex && (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0))
      fail(path, "the vertex element has no x, y and z properties");
    if (is_face && face_list < 0)
      fail(path, "the face element has no list property 'vertex_indices'");
    if (is_vertex) out.positions.resize(static_cast<std::size_t>(e.count));
    if (is_face)
      out.triangles.reserve(std::min(static_cast<std::size_t>(e.count), data_bytes / 4 + 1));

    // No properties: its rows hold nothing (and a huge count would loop for nothing; fuzzing).
    if (e.properties.empty()) continue;
    const std::string what = "element '" + e.name + "'";
    auto src = make_source(what);
    if (is_vertex && quality >= 0) out.vertex_quality.resize(out.positions.size());
    for (std::int64_t row = 0; row < e.count; ++row) {
      float row_quality = 0.0f;
      for (std::size_t i = 0; i < e.properties.size(); ++i) {
        const PlyProperty& p = e.properties[i];
        if (!p.is_list) {
          const int k = static_cast<int>(i);
          if (k == quality) {
            row_quality = static_cast<float>(src.scalar(p.type));
            if (is_vertex) out.vertex_quality[static_cast<std::size_t>(row)] = row_quality;
            continue;
          }
          const int axis = !is_vertex    ? -1
                           : k == xyz[0] ? 0
                           : k == xyz[1] ? 1
                           : k == xyz[2] ? 2
                                         : -1;
          if (axis >= 0) {
            out.positions[static_cast<std::size_t>(row)][axis] =
                static_cast<float>(src.scalar(p.type));
          } else {
            src.skip_scalar(p.type);
          }
          continue;
        }
        const double count_value = src.scalar(p.count_type);
        if (!(count_value >= 0.0) || count_value > static_cast<double>(data_bytes))
          fail(path, what + " row " + std::to_string(row) + " has an impossible list length");
        const auto n = static_cast<std::size_t>(count_value);
        if (static_cast<int>(i) != face_list) {
          for (std::size_t k = 0; k < n; ++k) src.skip_scalar(p.type);
          continue;
        }
        corners.resize(n);
        for (std::size_t k = 0; k < n; ++k) {
          const double index = src.scalar(p.type);
          if (!(index >= 0.0) || index >= static_cast<double>(vertex_count) ||
              index != static_cast<double>(static_cast<std::int64_t>(index)))
            fail(path, "face " + std::to_string(row) + " uses vertex " +
                           std::to_string(static_cast<long long>(index)) + " but the file has " +
                           std::to_string(vertex_count) + " vertices");
          corners[k] = static_cast<std::uint32_t>(index);
        }
        if (n < 3) ++skipped_faces;
        append_fan(out.triangles, corners.data(), corners.size());
      }
      if (is_face && quality >= 0) out.face_quality.resize(out.triangles.size(), row_quality);
    }
  }
  if (skipped_faces > 0)
    out.warnings.push_back("skipped " + std::to_string(skipped_faces) +
                           " faces with fewer than 3 vertices");
}


// --- Binary: each element's rows are decoded by a loop over a precomputed property table (no
// per-value dispatch through a cursor, no strings); fixed-size rows (vertices) in parallel.

template <typename T>
T load_raw(const char* p, bool swap) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, p, sizeof(T));
  if (swap) std::reverse(bytes, bytes + sizeof(T));
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

double load_value(const char* p, PlyType t, bool swap) {
  switch (t) {
    case PlyType::Int8: return static_cast<double>(load_raw<std::int8_t>(p, swap));
    case PlyType::UInt8: return static_cast<double>(load_raw<std::uint8_t>(p, swap));
    case PlyType::Int16: return static_cast<double>(load_raw<std::int16_t>(p, swap));
    case PlyType::UInt16: return static_cast<double>(load_raw<std::uint16_t>(p, swap));
    case PlyType::Int32: return static_cast<double>(load_raw<std::int32_t>(p, swap));
    case PlyType::UInt32: return static_cast<double>(load_raw<std::uint32_t>(p, swap));
    case PlyType::Float32: return static_cast<double>(load_raw<float>(p, swap));
    case PlyType::Float64: return load_raw<double>(p, swap);
  }
  return 0.0;
}

// An index as stored: integral types exactly, floats only when they hold an integer.
std::int64_t load_index(const char* p, PlyType t, bool swap) {
  switch (t) {
    case PlyType::Int32: return load_raw<std::int32_t>(p, swap);
    case PlyType::UInt32: return load_raw<std::uint32_t>(p, swap);
    default: break;
  }
  const double v = load_value(p, t, swap);
  if (!(v >= -1e18 && v <= 1e18) || v != std::floor(v)) return -1;
  return static_cast<std::int64_t>(v);
}

void read_binary(const std::string& path, const PlyHeader& h, std::int64_t vertex_count,
                 std::string_view data, const FileData* file, RawMesh& out) {
  const bool swap = (h.encoding == PlyEncoding::BinaryBig) != (std::endian::native == std::endian::big);
  std::size_t pos = h.data_start;
  std::size_t skipped_faces = 0;
  std::vector<std::uint32_t> corners;
  for (const PlyElement& e : h.elements) {
    const bool is_vertex = e.name == "vertex";
    const bool is_face = e.name == "face";
    const std::string what = "element '" + e.name + "'";
    const auto truncated = [&] { fail(path, "unexpected end of file while reading " + what); };
    // Byte offset of each scalar in a row (rows without lists), and where lists are.
    bool fixed = true;
    std::size_t row_bytes = 0;
    int xyz[3] = {-1, -1, -1}, face_list = -1, quality = -1;
    std::vector<std::size_t> offset(e.properties.size(), 0);
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const PlyProperty& p = e.properties[i];
      offset[i] = row_bytes;
      if (p.is_list) {
        fixed = false;
      } else {
        row_bytes += type_size(p.type);
      }
      const int k = static_cast<int>(i);
      if ((is_vertex || is_face) && !p.is_list && p.name == "quality") quality = k;
      if (is_vertex && !p.is_list) {
        if (p.name == "x") xyz[0] = k;
        if (p.name == "y") xyz[1] = k;
        if (p.name == "z") xyz[2] = k;
      }
      if (is_face && p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index")) face_list = k;
    }
    if (is_vertex && (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0))
      fail(path, "the vertex element has no x, y and z properties");
    if (is_face && face_list < 0) fail(path, "the face element has no list property 'vertex_indices'");
    const auto count = static_cast<std::size_t>(e.count);

    if (fixed) {
      if (row_bytes > 0 && count > (data.size() - pos) / row_bytes) truncated();
      const char* base = data.data() + pos;
      if (is_vertex) {
        out.positions.resize(count);
        if (quality >= 0) out.vertex_quality.resize(count);
        const PlyType tx = e.properties[static_cast<std::size_t>(xyz[0])].type;
        const bool packed_floats = !swap && row_bytes == 12 && offset[static_cast<std::size_t>(xyz[0])] == 0 &&
                                   offset[static_cast<std::size_t>(xyz[1])] == 4 &&
                                   offset[static_cast<std::size_t>(xyz[2])] == 8 && tx == PlyType::Float32 &&
                                   e.properties[static_cast<std::size_t>(xyz[1])].type == PlyType::Float32 &&
                                   e.properties[static_cast<std::size_t>(xyz[2])].type == PlyType::Float32;
        parallel_for(count, [&](std::size_t b, std::size_t end) {
          if (packed_floats) {
            if (end > b) std::memcpy(out.positions.data() + b, base + b * 12, (end - b) * 12);  // not with a null destination (0 vertices)
          } else {
            for (std::size_t row = b; row < end; ++row) {
              const char* r = base + row * row_bytes;
              for (int a = 0; a < 3; ++a) {
                const auto i = static_cast<std::size_t>(xyz[a]);
                out.positions[row][a] = static_cast<float>(load_value(r + offset[i], e.properties[i].type, swap));
              }
            }
          }
          if (quality >= 0) {
            const auto i = static_cast<std::size_t>(quality);
            for (std::size_t row = b; row < end; ++row)
              out.vertex_quality[row] =
                  static_cast<float>(load_value(base + row * row_bytes + offset[i], e.properties[i].type, swap));
          }
          if (file) file->release(pos + b * row_bytes, pos + end * row_bytes);
        }, 1 << 16);
      }
      pos += count * row_bytes;
      continue;
    }

    // Rows with lists: sequential. The common face row (uchar 3, three 32-bit indices) is
    // decoded without the general loop.
    if (is_vertex) {
      out.positions.resize(count);
      if (quality >= 0) out.vertex_quality.resize(count);
    }
    if (is_face) {
      out.triangles.reserve(std::min(count, (data.size() - pos) / 4 + 1));
      if (quality >= 0) out.face_quality.reserve(out.triangles.capacity());
    }
    const std::size_t end_of_data = data.size();
    const char* d = data.data();
    const bool fast_face = is_face && e.properties.size() == 1 && e.properties[0].count_type == PlyType::UInt8 &&
                           (e.properties[0].type == PlyType::Int32 || e.properties[0].type == PlyType::UInt32);
    const auto vmax = static_cast<std::uint64_t>(vertex_count);
    // A "3 a b c" row's three 32-bit indices from `at` into t; false when one is out of range
    // (a negative int32 is >= 2^31 here).
    const auto plain_indices = [&](const char* at, Triangle& t) {
      bool ok = true;
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = load_raw<std::uint32_t>(at + 4 * k, swap);
        ok = ok && v < vmax;
        t[static_cast<std::size_t>(k)] = v;
      }
      return ok;
    };
    // Rows that are all "3 a b c" (the usual binary triangle mesh) lie 13 bytes apart: then
    // they are decoded on all threads. Row k's count is read at pos + 13 k, which is where row
    // k starts when rows 0..k-1 all hold 3; any other count or an index out of range sends the
    // element to the sequential loop below, from its start (same result and errors).
    if (fast_face && count >= (std::size_t{1} << 16) && count <= (end_of_data - pos) / 13) {
      const std::size_t first = out.triangles.size();
      out.triangles.resize(first + count);
      std::atomic<bool> plain{true};
      const char* rows = d + pos;
      parallel_for(count, [&](std::size_t b, std::size_t end) {
        bool ok = true;
        for (std::size_t row = b; row < end && ok; ++row) {
          const char* r = rows + row * 13;
          ok = static_cast<unsigned char>(r[0]) == 3 && plain_indices(r + 1, out.triangles[first + row]);
        }
        if (!ok) plain = false;
        else if (file) file->release(pos + b * 13, pos + end * 13);
      }, 1 << 16);
      if (plain) {
        pos += count * 13;
        continue;
      }
      out.triangles.resize(first);
    }
    std::size_t released = pos;
    for (std::size_t row = 0; row < count; ++row) {
      if (fast_face && pos + 13 <= end_of_data && static_cast<unsigned char>(d[pos]) == 3) {
        Triangle t;
        if (!plain_indices(d + pos + 1, t)) {
          for (int k = 0; k < 3; ++k) {
            const std::int64_t v = load_index(d + pos + 1 + 4 * k, e.properties[0].type, swap);
            if (v < 0 || v >= vertex_count)
              fail(path, "face " + std::to_string(row) + " uses vertex " + std::to_string(v) +
                             " but the file has " + std::to_string(vertex_count) + " vertices");
          }
        }
        out.triangles.push_back(t);
        pos += 13;
      } else {
        float row_quality = 0.0f;
        for (std::size_t i = 0; i < e.properties.size(); ++i) {
          const PlyProperty& p = e.properties[i];
          if (!p.is_list) {
            const std::size_t sz = type_size(p.type);
            if (sz > end_of_data - pos) truncated();
            if (static_cast<int>(i) == quality) row_quality = static_cast<float>(load_value(d + pos, p.type, swap));
            for (int a = 0; a < 3; ++a)
              if (is_vertex && static_cast<int>(i) == xyz[a])
                out.positions[row][a] = static_cast<float>(load_value(d + pos, p.type, swap));
            pos += sz;
            continue;
          }
          const std::size_t csz = type_size(p.count_type);
          if (csz > end_of_data - pos) truncated();
          const double count_value = load_value(d + pos, p.count_type, swap);
          pos += csz;
          if (!(count_value >= 0.0) || count_value > static_cast<double>(end_of_data - h.data_start))
            fail(path, what + " row " + std::to_string(row) + " has an impossible list length");
          const auto n = static_cast<std::size_t>(count_value);
          const std::size_t isz = type_size(p.type);
          if (n * isz > end_of_data - pos) truncated();
          if (static_cast<int>(i) == face_list) {
            corners.resize(n);
            for (std::size_t k = 0; k < n; ++k) {
              const std::int64_t v = load_index(d + pos + k * isz, p.type, swap);
              if (v < 0 || v >= vertex_count)
                fail(path, "face " + std::to_string(row) + " uses vertex " + std::to_string(v) +
                               " but the file has " + std::to_string(vertex_count) + " vertices");
              corners[k] = static_cast<std::uint32_t>(v);
            }
            if (n < 3) ++skipped_faces;
            append_fan(out.triangles, corners.data(), corners.size());
          }
          pos += n * isz;
        }
        if (is_face && quality >= 0) out.face_quality.resize(out.triangles.size(), row_quality);
        if (is_vertex && quality >= 0) out.vertex_quality[row] = row_quality;
        continue;
      }
      if (is_face && quality >= 0) out.face_quality.resize(out.triangles.size(), 0.0f);
      if (file && pos - released > (std::size_t{1} << 24)) {
        file->release(released, pos);
        released = pos;
      }
    }
  }
  if (skipped_faces > 0)
    out.warnings.push_back("skipped " + std::to_string(skipped_faces) + " faces with fewer than 3 vertices");
}

}  // namespace

RawMesh read_ply(const std::string& path, std::string_view data, const FileData* file) {
  const PlyHeader h = parse_header(path, data);
  const std::size_t data_bytes = data.size() - h.data_start;

  // The declared counts must fit in the file before anything is allocated.
  double needed = 0.0;
  std::int64_t vertex_count = 0;
  for (const PlyElement& e : h.elements) {
    needed += static_cast<double>(e.count) * min_row_bytes(e, h.encoding);
    if (e.name == "vertex") vertex_count = e.count;
  }
  if (needed > static_cast<double>(data_bytes) + 1.0)
    fail(path, "the header declares more elements than the file's " + std::to_string(data.size()) +
                   " bytes can hold (truncated file?)");
  if (vertex_count > static_cast<std::int64_t>(UINT32_MAX)) fail(path, "too many vertices");
  std::int64_t face_count = 0;
  for (const PlyElement& e : h.elements) {  // LoadOptions limits, then the memory this run needs
    if (e.name == "vertex") check_vertex_count(path, static_cast<std::uint64_t>(e.count));
    if (e.name == "face") {
      check_triangle_count(path, static_cast<std::uint64_t>(e.count), "faces");
      face_count = e.count;
    }
  }
  check_mesh_fits(path, static_cast<std::uint64_t>(vertex_count), static_cast<std::uint64_t>(face_count));

  RawMesh out;
  if (h.encoding == PlyEncoding::Ascii) {
    TextCursor c(data, path, h.data_start);
    read_elements(
        path, h, vertex_count, data_bytes,
        [&](const std::string& what) {
          return AsciiSource{c, what};
        },
        out);
  } else {
    read_binary(path, h, vertex_count, data, file, out);
  }
  return out;
}

}  // namespace sdfkit::io::detail

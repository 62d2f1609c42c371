// write_field, the colour map, atomic file replacement, and the .txt and PLY writers.

#include "sdfkit/io/asset.hpp"

#include "writers.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <random>

namespace sdfkit::io {

glm::vec3 colormap(float t) {
  if (!(t > 0.0f)) t = 0.0f;  // also NaN
  if (t > 1.0f) t = 1.0f;
  // Hue from 0 deg (red) to 240 deg (blue) at full saturation and value: the stops red,
  // yellow, green, cyan, blue sit at t = 0, 1/4, 1/2, 3/4, 1.
  const float h = t * 4.0f;  // [0,4]
  const int segment = std::min(3, static_cast<int>(h));
  const float f = h - static_cast<float>(segment);
  switch (segment) {
    case 0: return {1.0f, f, 0.0f};          // red -> yellow
    case 1: return {1.0f - f, 1.0f, 0.0f};   // yellow -> green
    case 2: return {0.0f, 1.0f, f};          // green -> cyan
    default: return {0.0f, 1.0f - f, 1.0f};  // cyan -> blue
  }
}

namespace {

[[noreturn]] void io_fail(const std::string& path, const std::string& what, int err) {
  throw Error(path + ": " + what + " (" + std::strerror(err) + ")");
}

// A temporary file name next to `path` that did not exist, created with mode 0666 & ~umask.
std::string create_temporary(const std::string& path) {
  std::random_device rd;
  std::mt19937_64 rng((static_cast<std::uint64_t>(rd()) << 32) ^ rd() ^
                      static_cast<std::uint64_t>(::getpid()));
  static constexpr char kAlphabet[] = "abcdefghijklmnopqrstuvwxyz0123456789";
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string name = path + ".tmp-";
    for (int i = 0; i < 8; ++i) name += kAlphabet[rng() % (sizeof(kAlphabet) - 1)];
    const int fd = ::open(name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      return name;
    }
    if (errno != EEXIST) io_fail(path, "cannot create a temporary file next to it", errno);
  }
  throw Error(path + ": cannot create a temporary file next to it");
}

void sync_file(const std::string& name, const std::string& path) {
  const int fd = ::open(name.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) io_fail(path, "cannot reopen the temporary file", errno);
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) io_fail(path, "cannot flush the file to disk", err);
}

}  // namespace

void write_file_atomically(const std::string& path,
                           const std::function<void(std::ostream&)>& write) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw Error(path + ": is a directory");
  const std::string temp = create_temporary(path);
  try {
    {
      std::ofstream out(temp, std::ios::binary | std::ios::trunc);
      if (!out) io_fail(path, "cannot open the temporary file", errno);
      write(out);
      out.flush();
      if (!out) io_fail(path, "cannot write the file", errno);
      out.close();
      if (out.fail()) io_fail(path, "cannot write the file", errno);
    }
    sync_file(temp, path);
    if (std::rename(temp.c_str(), path.c_str()) != 0)
      io_fail(path, "cannot replace the file", errno);
  } catch (...) {
    std::remove(temp.c_str());
    throw;
  }
}

namespace detail {

void write_txt(std::ostream& out, const OutputValues& values, bool normalized) {
  const std::vector<float>& v = normalized ? values.normalized : values.raw;
  std::string text;
  text.reserve(v.size() * 12);
  char buffer[64];
  for (const float x : v) {
    // %.9g: enough digits to read back the same float.
    const auto [end, ec] =
        std::to_chars(buffer, buffer + sizeof buffer, x, std::chars_format::general, 9);
    (void)ec;
    text.append(buffer, end);
    text += '\n';
  }
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
}

namespace {

template <typename T>
void put_le(std::string& s, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
  s.append(bytes, sizeof(T));
}

void put_color(std::string& s, float t) {
  const glm::vec3 c = colormap(t);
  for (int k = 0; k < 3; ++k)
    s += static_cast<char>(static_cast<std::uint8_t>(std::lround(c[k] * 255.0f)));
}

}  // namespace

void write_ply(std::ostream& out, std::span<const glm::vec3> positions, std::span<const Triangle> triangles,
               const OutputValues& values,
               const WriteOptions& options) {
  const bool per_vertex = values.domain == SdfDomain::Vertex;
  const std::vector<float>& q = options.normalized ? values.normalized : values.raw;
  std::string color_props;
  if (options.color)
    color_props = "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  std::string header = "ply\nformat binary_little_endian 1.0\n";
  header += std::string("comment sdfkit shape diameter function, per ") +
            (per_vertex ? "vertex" : "face") +
            (options.normalized ? ", normalized to [0,1]" : ", model units") + "\n";
  header += "element vertex " + std::to_string(positions.size()) + "\n";
  header += "property float x\nproperty float y\nproperty float z\n";
  if (per_vertex) header += "property float quality\n" + color_props;
  header += "element face " + std::to_string(triangles.size()) + "\n";
  header += "property list uchar int vertex_indices\n";
  if (!per_vertex) header += "property float quality\n" + color_props;
  header += "end_header\n";
  out.write(header.data(), static_cast<std::streamsize>(header.size()));

  // The body goes out in blocks of about 1 MiB, not as one string the size of the file (13M
  // triangles: 300 MB beside the mesh at the run's peak).
  constexpr std::size_t kBlock = std::size_t{1} << 20;
  std::string body;
  body.reserve(kBlock + 64);
  const auto flush = [&](bool last) {
    if (!last && body.size() < kBlock) return;
    out.write(body.data(), static_cast<std::streamsize>(body.size()));
    body.clear();
  };
  for (std::size_t v = 0; v < positions.size(); ++v) {
    flush(false);
    const glm::vec3& p = positions[v];
    put_le(body, p.x);
    put_le(body, p.y);
    put_le(body, p.z);
    if (per_vertex) {
      put_le(body, q[v]);
      if (options.color) put_color(body, values.normalized[v]);
    }
  }
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    flush(false);
    body += static_cast<char>(3);
    for (const std::uint32_t i : triangles[f])
      put_le(body, static_cast<std::int32_t>(i));
    if (!per_vertex) {
      put_le(body, q[f]);
      if (options.color) put_color(body, values.normalized[f]);
    }
  }
  flush(true);
}

}  // namespace detail

void check_output(const std::string& out_path, SdfDomain domain) {
  const std::optional<Format> named = format_of_extension(out_path);
  if (!named || *named == Format::Obj || *named == Format::Off) {
    const std::string ext = std::filesystem::path(out_path).extension().string();
    throw UsageError(out_path + ": " +
                     (ext.empty() ? std::string("no file extension")
                      : named     ? "cannot store values in " + ext + " files"
                                  : "unknown extension '" + ext + "'") +
                     "; write .gltf, .glb, .ply or .txt");
  }
  const Format format = *named;
  if ((format == Format::Gltf || format == Format::Glb) && domain != SdfDomain::Vertex)
    throw UsageError(out_path + ": per-face values cannot be stored in glTF; write .ply or .txt");
}

void write_field(const std::string& out_path, const Asset& asset, const SdfField& field,
                 const WriteOptions& options) {
  write_field(out_path, asset, asset.mesh, field, options);
}

void write_field(const std::string& out_path, const Asset& asset, const Mesh& mesh, const SdfField& field,
                 const WriteOptions& options) {
  check_output(out_path, field.domain);
  const Format format = format_from_path(out_path);
  const bool per_vertex = field.domain == SdfDomain::Vertex;
  const std::size_t expected = per_vertex ? mesh.vertex_count() : mesh.face_count();
  if (field.values.size() != expected)
    throw InputError(out_path + ": the field has " + std::to_string(field.values.size()) +
                     " values but the mesh has " + std::to_string(expected) +
                     (per_vertex ? " vertices" : " faces"));
  // An asset whose input is its own welded mesh: input_positions, input_triangles and
  // input_to_welded all empty beside a mesh (what run_compute makes of an asset whose welding
  // merged nothing, to hold one copy of the mesh instead of two). Written as PLY or txt only.
  const bool input_is_mesh = asset.input_positions.empty() && asset.input_triangles.empty() &&
                             asset.input_to_welded.empty() && !mesh.triangles.empty();
  if (input_is_mesh && format != Format::Ply && format != Format::Txt)
    throw Error(out_path + ": an asset without its input copy is written as .ply or .txt only");
  const std::span<const glm::vec3> input_positions = input_is_mesh ? mesh.positions : asset.input_positions;
  const std::span<const Triangle> input_triangles = input_is_mesh ? mesh.triangles : asset.input_triangles;
  if (per_vertex && !input_is_mesh && asset.input_to_welded.size() != asset.input_positions.size())
    throw InputError(out_path + ": the asset's input-to-welded map does not match its vertices");
  if (!per_vertex && input_triangles.size() != mesh.face_count())
    throw InputError(out_path + ": the asset's input triangles do not match its mesh");
  if (!options.texcoord1.empty()) {
    if (format != Format::Gltf && format != Format::Glb)
      throw UsageError(out_path + ": a TEXCOORD_1 UV set can only be written to .gltf or .glb");
    if (asset.format == Format::Gltf || asset.format == Format::Glb)
      throw UsageError(out_path + ": a TEXCOORD_1 UV set is only written into a fresh glTF (the input is a glTF "
                       "asset, whose primitives would have to be split at the atlas's chart borders)");
    if (options.texcoord1.size() != asset.input_triangles.size())
      throw InputError(out_path + ": " + std::to_string(options.texcoord1.size()) + " TEXCOORD_1 triangles for " +
                       std::to_string(asset.input_triangles.size()) + " input triangles");
    for (const auto& t : options.texcoord1)
      for (const glm::vec2& uv : t)
        if (!std::isfinite(uv.x) || !std::isfinite(uv.y))
          throw InputError(out_path + ": a TEXCOORD_1 coordinate is not finite");
  }

  // Values in input order: per input vertex through the weld map; faces keep their order.
  detail::OutputValues values;
  values.domain = field.domain;
  const std::vector<float> norm = normalized(field.values);
  if (per_vertex && input_is_mesh) {
    values.raw = field.values;
    values.normalized = norm;
  } else if (per_vertex) {
    values.raw.resize(asset.input_to_welded.size());
    values.normalized.resize(asset.input_to_welded.size());
    for (std::size_t i = 0; i < asset.input_to_welded.size(); ++i) {
      const std::uint32_t w = asset.input_to_welded[i];
      if (w >= field.values.size())
        throw InputError(out_path + ": the asset's input-to-welded map is out of range");
      values.raw[i] = field.values[w];
      values.normalized[i] = norm[w];
    }
  } else {
    values.raw = field.values;
    values.normalized = norm;
  }

  std::vector<std::string> warnings;
  write_file_atomically(out_path, [&](std::ostream& out) {
    switch (format) {
      case Format::Txt: detail::write_txt(out, values, options.normalized); break;
      case Format::Ply: detail::write_ply(out, input_positions, input_triangles, values, options); break;
      case Format::Gltf:
      case Format::Glb:
        detail::write_gltf(out, format == Format::Glb, asset, values, options, warnings);
        break;
      case Format::Obj:
      case Format::Off: break;
    }
  });
  for (const std::string& w : warnings) log_warning(out_path + ": " + w);
}

}  // namespace sdfkit::io

// load_asset: format dispatch, file access, validation and welding shared by every reader.

#include "sdfkit/io/asset.hpp"

#include "readers.hpp"

#include "sdfkit/core/log.hpp"
#include "sdfkit/core/weld.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace sdfkit::io {
namespace detail {

void fail(const std::string& path, const std::string& problem) {
  throw InputError(path + ": " + problem);
}

void check_regular_file(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) fail(path, "no such file");
  if (std::filesystem::is_directory(status)) fail(path, "is a directory, not a mesh file");
  if (!std::filesystem::is_regular_file(status)) fail(path, "is not a regular file");
}

std::string read_file(const std::string& path, std::uint64_t max_size) {
  check_regular_file(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::string("cannot open the file (") + std::strerror(errno) + ")");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) fail(path, "cannot read the file size");
  if (max_size > 0 && static_cast<std::uint64_t>(size) > max_size)
    fail(path, "the file has " + std::to_string(size) + " bytes, more than the limit of " +
                   std::to_string(max_size) + " (max_file_size, --max-file-size)");
  in.seekg(0, std::ios::beg);
  std::string data(static_cast<std::size_t>(size), '\0');
  if (size > 0 && !in.read(data.data(), size)) fail(path, "cannot read the file");
  return data;
}

namespace {
thread_local ReadLimits current_limits;
}  // namespace

ScopedReadLimits::ScopedReadLimits(const LoadOptions& options) : saved_(current_limits) {
  current_limits.max_triangles = options.max_triangles;
  current_limits.max_vertices =
      options.max_triangles > UINT64_MAX / 3 ? 0 : 3 * options.max_triangles;
}

ScopedReadLimits::~ScopedReadLimits() { current_limits = saved_; }

void check_triangle_count(const std::string& path, std::uint64_t count, const char* what) {
  const std::uint64_t max = current_limits.max_triangles;
  if (max > 0 && count > max)
    fail(path, std::to_string(count) + " " + what + ", more than the limit of " +
                   std::to_string(max) + " triangles (max_triangles, --max-triangles)");
}

void check_vertex_count(const std::string& path, std::uint64_t count) {
  const std::uint64_t max = current_limits.max_vertices;
  if (max > 0 && count > max)
    fail(path, std::to_string(count) + " vertices, more than the limit of " +
                   std::to_string(max) + " (3 x max_triangles, --max-triangles)");
}

void append_fan(std::vector<Triangle>& triangles, const std::uint32_t* corners, std::size_t n) {
  for (std::size_t k = 1; k + 1 < n; ++k)
    triangles.push_back(Triangle{corners[0], corners[k], corners[k + 1]});
}

}  // namespace detail

Format format_from_path(const std::string& path) {
  const std::string ext_raw = std::filesystem::path(path).extension().string();
  std::string ext = ext_raw;
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  if (ext == ".gltf") return Format::Gltf;
  if (ext == ".glb") return Format::Glb;
  if (ext == ".obj") return Format::Obj;
  if (ext == ".off") return Format::Off;
  if (ext == ".ply") return Format::Ply;
  if (ext == ".txt") return Format::Txt;
  if (ext.empty()) detail::fail(path, "no file extension (expected .gltf, .glb, .obj, .off, .ply)");
  detail::fail(path,
               "unknown extension '" + ext_raw + "' (expected .gltf, .glb, .obj, .off, .ply)");
}

const char* format_name(Format format) {
  switch (format) {
    case Format::Gltf: return "gltf";
    case Format::Glb: return "glb";
    case Format::Obj: return "obj";
    case Format::Off: return "off";
    case Format::Ply: return "ply";
    case Format::Txt: return "txt";
  }
  return "unknown";
}

void validate_load_options(const LoadOptions& options) {
  if (!(options.weld_tolerance >= 0.0f) || !std::isfinite(options.weld_tolerance))
    throw InputError("weld tolerance must be a finite number >= 0");
}

Asset load_asset(const std::string& path, const LoadOptions& options) {
  const Format format = format_from_path(path);
  if (format == Format::Txt)
    detail::fail(path, ".txt files hold values, not meshes (load .gltf, .glb, .obj, .off or .ply)");
  validate_load_options(options);
  return detail::load_from_memory(path, format, detail::read_file(path, options.max_file_size),
                                  options);
}

namespace detail {

Asset load_from_memory(const std::string& path, Format format, std::string_view data,
                       const LoadOptions& options) {
  validate_load_options(options);
  RawMesh raw;
  {
    const ScopedReadLimits limits(options);
    switch (format) {
      case Format::Off: raw = read_off(path, data); break;
      case Format::Obj: raw = read_obj(path, data); break;
      case Format::Ply: raw = read_ply(path, data); break;
      case Format::Gltf:
      case Format::Glb: raw = read_gltf(path, data, format == Format::Glb, options); break;
      case Format::Txt:
        fail(path, ".txt files hold values, not meshes (load .gltf, .glb, .obj, .off or .ply)");
    }
    // Readers check counts where a file declares them; OBJ declares none (its memory is bounded
    // by the file size): every format is held to the limits here, before welding.
    check_vertex_count(path, raw.positions.size());
    check_triangle_count(path, raw.triangles.size());
  }

  Asset asset;
  asset.path = path;
  asset.format = format;
  asset.input_positions = std::move(raw.positions);
  asset.input_triangles = std::move(raw.triangles);
  asset.warnings = std::move(raw.warnings);
  asset.source = std::move(raw.source);
  for (const std::string& w : asset.warnings) log_warning(path + ": " + w);

  {
    // validate_mesh wants a Mesh; check the input before welding (weld assumes valid indices).
    Mesh input;
    input.positions = std::move(asset.input_positions);
    input.triangles = std::move(asset.input_triangles);
    validate_mesh(input, path);
    asset.input_positions = std::move(input.positions);
    asset.input_triangles = std::move(input.triangles);
  }

  WeldResult welded = weld(asset.input_positions, asset.input_triangles, options.weld_tolerance);
  asset.mesh = std::move(welded.mesh);
  asset.input_to_welded = std::move(welded.input_to_welded);
  return asset;
}

}  // namespace detail
}  // namespace sdfkit::io

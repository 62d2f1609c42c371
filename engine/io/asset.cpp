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

std::string read_file(const std::string& path) {
  check_regular_file(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::string("cannot open the file (") + std::strerror(errno) + ")");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) fail(path, "cannot read the file size");
  in.seekg(0, std::ios::beg);
  std::string data(static_cast<std::size_t>(size), '\0');
  if (size > 0 && !in.read(data.data(), size)) fail(path, "cannot read the file");
  return data;
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

float weld_tolerance_for(const LoadOptions& options, std::span<const glm::vec3> positions) {
  return options.weld_tolerance >= 0.0f ? options.weld_tolerance : default_weld_tolerance(positions);
}

Asset load_asset(const std::string& path, const LoadOptions& options) {
  const Format format = format_from_path(path);
  if (format == Format::Txt)
    detail::fail(path, ".txt files hold values, not meshes (load .gltf, .glb, .obj, .off or .ply)");
  if (!std::isfinite(options.weld_tolerance))
    throw InputError("weld tolerance must be a finite number >= 0");

  detail::check_regular_file(path);
  detail::RawMesh raw;
  switch (format) {
    case Format::Off: raw = detail::read_off(path, detail::read_file(path)); break;
    case Format::Obj: raw = detail::read_obj(path, detail::read_file(path)); break;
    case Format::Ply: raw = detail::read_ply(path, detail::read_file(path)); break;
    case Format::Gltf:
    case Format::Glb: raw = detail::read_gltf(path, format == Format::Glb); break;
    case Format::Txt: break;
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

  asset.weld_tolerance = weld_tolerance_for(options, asset.input_positions);
  WeldResult welded = weld(asset.input_positions, asset.input_triangles, asset.weld_tolerance);
  asset.mesh = std::move(welded.mesh);
  asset.input_to_welded = std::move(welded.input_to_welded);
  return asset;
}

}  // namespace sdfkit::io

#pragma once
// Internal to sdfkit_io: the per-format readers and the helpers they share.

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/mesh.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace sdfkit::io::detail {

// What a reader produces: input vertices and triangles in input order, before welding.
struct RawMesh {
  std::vector<glm::vec3> positions;
  std::vector<Triangle> triangles;
  std::vector<std::string> warnings;
  std::shared_ptr<const void> source;  // glTF: the model kept for write-back
};

// Throws InputError("<path>: <problem>").
[[noreturn]] void fail(const std::string& path, const std::string& problem);

// Throws InputError unless `path` names an existing regular file.
void check_regular_file(const std::string& path);

// The whole file as bytes. Throws InputError for a missing file, a directory, an unreadable
// file.
std::string read_file(const std::string& path);

// Readers: `data` is the whole file. Each throws InputError naming `path` on malformed input;
// indices are checked against the vertex count, coordinates are not (load_asset validates).
RawMesh read_off(const std::string& path, std::string_view data);
RawMesh read_obj(const std::string& path, std::string_view data);
RawMesh read_ply(const std::string& path, std::string_view data);
RawMesh read_gltf(const std::string& path, bool binary);

// Appends the fan triangulation (v0 v1 v2, v0 v2 v3, ...) of a polygon given by its corners.
void append_fan(std::vector<Triangle>& triangles, const std::uint32_t* corners, std::size_t n);

}  // namespace sdfkit::io::detail

#pragma once
// Internal to sdfkit_io: the per-format readers and the helpers they share.

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/mesh.hpp"
#include "sdfkit/io/asset.hpp"

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
  // PLY only: the scalar property `quality` of the vertex element (one per vertex) and of the
  // face element (one per triangle: a polygon's value repeats over its fan); empty when absent.
  std::vector<float> vertex_quality;
  std::vector<float> face_quality;
};

// Throws InputError("<path>: <problem>").
[[noreturn]] void fail(const std::string& path, const std::string& problem);

// Throws InputError unless `path` names an existing regular file.
void check_regular_file(const std::string& path);

// The whole file as bytes. Throws InputError for a missing file, a directory, an unreadable
// file, or one larger than max_size bytes (0 = no limit), refused before it is read.
std::string read_file(const std::string& path, std::uint64_t max_size = 0);

// Resource limits for the readers. load_asset sets them (ScopedReadLimits) for the reader it
// calls on this thread; a reader calls the checks where a count is first known (a header's
// element count, an accessor's count), before allocating for it. Without a scope: no limit.
struct ReadLimits {
  std::uint64_t max_triangles = 0;  // 0 = none
  std::uint64_t max_vertices = 0;   // 0 = none
};
class ScopedReadLimits {
public:
  explicit ScopedReadLimits(const LoadOptions& options);
  ~ScopedReadLimits();
  ScopedReadLimits(const ScopedReadLimits&) = delete;
  ScopedReadLimits& operator=(const ScopedReadLimits&) = delete;

private:
  ReadLimits saved_;
};
// Throws InputError "<path>: <count> <what>, more than the limit of <max> triangles
// (max_triangles, --max-triangles)" when `count` things that each make at least one triangle
// (triangles, faces, polygons) pass the limit.
void check_triangle_count(const std::string& path, std::uint64_t count,
                          const char* what = "triangles");
// The same for vertices (limit: 3 x max_triangles).
void check_vertex_count(const std::string& path, std::uint64_t count);

// Readers: `data` is the whole file. Each throws InputError naming `path` on malformed input;
// indices are checked against the vertex count, coordinates are not (load_asset validates).
RawMesh read_off(const std::string& path, std::string_view data);
RawMesh read_obj(const std::string& path, std::string_view data);
RawMesh read_ply(const std::string& path, std::string_view data);
// glTF: `data` is the .gltf text or the .glb bytes; external files resolve as `options` says.
RawMesh read_gltf(const std::string& path, std::string_view data, bool binary,
                  const LoadOptions& options);

// load_asset after the file was read: the reader of `format`, the limits, validation and
// welding (the fuzz harnesses' entry point).
Asset load_from_memory(const std::string& path, Format format, std::string_view data,
                       const LoadOptions& options);

// Appends the fan triangulation (v0 v1 v2, v0 v2 v3, ...) of a polygon given by its corners.
void append_fan(std::vector<Triangle>& triangles, const std::uint32_t* corners, std::size_t n);

}  // namespace sdfkit::io::detail

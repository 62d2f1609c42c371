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

// A file's bytes, memory-mapped read-only (no copy: pages come from the page cache as they are
// read). release() hands a range already parsed back to the kernel, so a reader's resident
// memory is its output, not the file. Move-only.
class FileData {
public:
  FileData() = default;
  FileData(FileData&& other) noexcept { *this = std::move(other); }
  FileData& operator=(FileData&& other) noexcept;
  FileData(const FileData&) = delete;
  FileData& operator=(const FileData&) = delete;
  ~FileData();

  std::string_view view() const { return {data_, size_}; }
  operator std::string_view() const { return view(); }  // NOLINT: a view of the bytes
  // Drops the whole pages inside [begin, end) from this process's resident memory (they are
  // read again from the page cache if touched later). A no-op for small files.
  void release(std::size_t begin, std::size_t end) const;

private:
  friend FileData read_file(const std::string& path, std::uint64_t max_size);
  const char* data_ = nullptr;
  std::size_t size_ = 0;
  bool mapped_ = false;
};

// The whole file. Throws InputError for a missing file, a directory, an unreadable file, or one
// larger than max_size bytes (0 = no limit), refused before it is read.
FileData read_file(const std::string& path, std::uint64_t max_size = 0);

// Throws InputError "<path>: a mesh of V vertices and F triangles needs about X GiB to process,
// more than the Y GiB of memory available" when the estimated memory of a whole run (input,
// welded copy, BVH, device buffers, output; `bytes_per_vertex` / `bytes_per_triangle` measured
// on a 13M-triangle run) exceeds the memory this process can get (MemAvailable, and the cgroup's
// limit where one is set, and SDFKIT_MEMORY_LIMIT in bytes where set). Readers call it as soon as they know the counts, before allocating.
void check_mesh_fits(const std::string& path, std::uint64_t vertices, std::uint64_t triangles);

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
// `file` (optional): the mapping `data` comes from, whose parsed pages the reader releases.
RawMesh read_ply(const std::string& path, std::string_view data, const FileData* file = nullptr);
// glTF: `data` is the .gltf text or the .glb bytes; external files resolve as `options` says.
RawMesh read_gltf(const std::string& path, std::string_view data, bool binary,
                  const LoadOptions& options);

// load_asset after the file was read: the reader of `format`, the limits, validation and
// welding (the fuzz harnesses' entry point). `file` (optional): the mapping `data` comes from.
Asset load_from_memory(const std::string& path, Format format, std::string_view data,
                       const LoadOptions& options, const FileData* file = nullptr);

// Appends the fan triangulation (v0 v1 v2, v0 v2 v3, ...) of a polygon given by its corners.
void append_fan(std::vector<Triangle>& triangles, const std::uint32_t* corners, std::size_t n);

}  // namespace sdfkit::io::detail

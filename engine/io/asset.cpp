// load_asset: format dispatch, file access, validation and welding shared by every reader.

#include "sdfkit/io/asset.hpp"

#include "readers.hpp"

#include "sdfkit/core/log.hpp"
#include "sdfkit/core/orient.hpp"
#include "sdfkit/core/weld.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <utility>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

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

FileData& FileData::operator=(FileData&& other) noexcept {
  if (this != &other) {
    this->~FileData();
    data_ = std::exchange(other.data_, nullptr);
    size_ = std::exchange(other.size_, 0);
    mapped_ = std::exchange(other.mapped_, false);
  }
  return *this;
}

FileData::~FileData() {
  if (mapped_) munmap(const_cast<char*>(data_), size_);
  else delete[] data_;
  data_ = nullptr;
  size_ = 0;
  mapped_ = false;
}

void FileData::release(std::size_t begin, std::size_t end) const {
  if (!mapped_) return;
  static const std::size_t page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  const std::size_t first = (begin + page - 1) / page * page;
  const std::size_t last = std::min(end, size_) / page * page;
  if (last > first) madvise(const_cast<char*>(data_) + first, last - first, MADV_DONTNEED);
}

FileData read_file(const std::string& path, std::uint64_t max_size) {
  check_regular_file(path);
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail(path, std::string("cannot open the file (") + std::strerror(errno) + ")");
  struct stat st {};
  if (fstat(fd, &st) != 0) {
    const int e = errno;
    close(fd);
    fail(path, std::string("cannot read the file size (") + std::strerror(e) + ")");
  }
  if (max_size > 0 && static_cast<std::uint64_t>(st.st_size) > max_size) {
    close(fd);
    fail(path, "the file has " + std::to_string(st.st_size) + " bytes, more than the limit of " +
                   std::to_string(max_size) + " (max_file_size, --max-file-size)");
  }
  FileData f;
  f.size_ = static_cast<std::size_t>(st.st_size);
  if (f.size_ > 0) {
    void* p = mmap(nullptr, f.size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (p != MAP_FAILED) {
      madvise(p, f.size_, MADV_SEQUENTIAL);
      f.data_ = static_cast<const char*>(p);
      f.mapped_ = true;
    } else {
      // Not mappable (some file systems): read it.
      auto* buf = new char[f.size_];
      f.data_ = buf;
      std::size_t done = 0;
      while (done < f.size_) {
        const ssize_t n = ::read(fd, buf + done, f.size_ - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
          const int e = errno;
          close(fd);
          fail(path, std::string("cannot read the file (") + (n == 0 ? "it shrank while read" : std::strerror(e)) + ")");
        }
        done += static_cast<std::size_t>(n);
      }
    }
  }
  close(fd);
  return f;
}

namespace {

// Bytes a process may still use: MemAvailable, capped by a cgroup v2 or v1 memory limit and by
// SDFKIT_MEMORY_LIMIT (bytes) where set.
std::uint64_t available_memory() {
  std::uint64_t avail = 0;
  if (const char* env = std::getenv("SDFKIT_MEMORY_LIMIT"); env && *env) {
    char* end = nullptr;
    const unsigned long long v = std::strtoull(env, &end, 10);
    if (end && *end == '\0' && v > 0) avail = v;
  }
  if (std::ifstream m("/proc/meminfo"); m) {
    std::string key;
    std::uint64_t kib = 0;
    std::string unit;
    while (m >> key >> kib >> unit)
      if (key == "MemAvailable:") {
        if (avail == 0 || kib * 1024 < avail) avail = kib * 1024;
        break;
      }
  }
  for (const char* limit_file : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream l(limit_file);
    std::uint64_t limit = 0;
    if (l >> limit && limit > 0 && (avail == 0 || limit < avail)) avail = limit;
  }
  return avail;
}

}  // namespace

void check_mesh_fits(const std::string& path, std::uint64_t vertices, std::uint64_t triangles) {
  // Measured on the 13.3M-triangle armadillo (6.7M vertices, sdfkit bench --huge, 30 rays per
  // vertex): a peak of 2539 MiB, 200 bytes per triangle (2858 MiB with 1 ray, where filling
  // the points without a hit adds the mesh's adjacency). This estimate gives 2894 MiB there; the
  // per-vertex part covers meshes of split vertices. A 50M-triangle mesh: about 10.6 GiB.
  constexpr double kBytesPerVertex = 96.0, kBytesPerTriangle = 180.0;
  const double need = kBytesPerVertex * static_cast<double>(vertices) + kBytesPerTriangle * static_cast<double>(triangles);
  const std::uint64_t avail = available_memory();
  if (avail == 0 || need <= static_cast<double>(avail)) return;
  char msg[256];
  std::snprintf(msg, sizeof msg,
                "a mesh of %llu vertices and %llu triangles needs about %.1f GiB to process, more than the %.1f GiB "
                "of memory available",
                static_cast<unsigned long long>(vertices), static_cast<unsigned long long>(triangles),
                need / 1073741824.0, static_cast<double>(avail) / 1073741824.0);
  fail(path, msg);
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

std::optional<Format> format_of_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  if (ext == ".gltf") return Format::Gltf;
  if (ext == ".glb") return Format::Glb;
  if (ext == ".obj") return Format::Obj;
  if (ext == ".off") return Format::Off;
  if (ext == ".ply") return Format::Ply;
  if (ext == ".txt") return Format::Txt;
  return std::nullopt;
}

Format format_from_path(const std::string& path) {
  if (const std::optional<Format> f = format_of_extension(path)) return *f;
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext.empty()) detail::fail(path, "no file extension (expected .gltf, .glb, .obj, .off, .ply)");
  detail::fail(path, "unknown extension '" + ext + "' (expected .gltf, .glb, .obj, .off, .ply)");
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
  // Negative: the default tolerance (LoadOptions::kDefaultWeld); NaN and infinities are refused.
  if (!std::isfinite(options.weld_tolerance))
    throw InputError("weld tolerance must be a finite number >= 0");
}

float weld_tolerance_for(const LoadOptions& options, std::span<const glm::vec3> positions) {
  return options.weld_tolerance >= 0.0f ? options.weld_tolerance : default_weld_tolerance(positions);
}

Asset load_asset(const std::string& path, const LoadOptions& options) {
  const Format format = format_from_path(path);
  if (format == Format::Txt)
    detail::fail(path, ".txt files hold values, not meshes (load .gltf, .glb, .obj, .off or .ply)");
  validate_load_options(options);
  const detail::FileData file = detail::read_file(path, options.max_file_size);
  return detail::load_from_memory(path, format, file, options, &file);
}

namespace detail {

Asset load_from_memory(const std::string& path, Format format, std::string_view data,
                       const LoadOptions& options, const FileData* file) {
  validate_load_options(options);
  const auto start = std::chrono::steady_clock::now();
  const auto ms_since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
  };
  RawMesh raw;
  {
    const ScopedReadLimits limits(options);
    switch (format) {
      case Format::Off: raw = read_off(path, data); break;
      case Format::Obj: raw = read_obj(path, data); break;
      case Format::Ply: raw = read_ply(path, data, file); break;
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

  asset.load_stages.push_back({"read", ms_since(start)});
  const auto weld_start = std::chrono::steady_clock::now();
  asset.weld_tolerance = weld_tolerance_for(options, asset.input_positions);
  WeldResult welded = weld(asset.input_positions, asset.input_triangles, asset.weld_tolerance);
  asset.mesh = std::move(welded.mesh);
  asset.input_to_welded = std::move(welded.input_to_welded);
  asset.load_stages.push_back({"weld", ms_since(weld_start)});
  // On the welded mesh: the input's UV and normal seams would cut its pieces apart.
  const auto orient_start = std::chrono::steady_clock::now();
  const OrientReport orientation = orient_outward(asset.mesh);
  asset.flipped_faces = orientation.flipped_faces;
  if (const std::string w = orientation.summary(); !w.empty()) {
    asset.warnings.push_back(w);
    log_warning(path + ": " + w);
  }
  asset.load_stages.push_back({"orient", ms_since(orient_start)});
  return asset;
}

}  // namespace detail
}  // namespace sdfkit::io

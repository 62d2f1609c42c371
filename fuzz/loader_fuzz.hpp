#pragma once
// Shared body of the loader fuzz harnesses: one input = the bytes of one file of a fixed format,
// loaded as load_asset loads a file (reader, limits, validation, welding). A file the loader
// refuses must be an InputError; anything else (a crash, a sanitizer report, another exception,
// a hang) is a finding.

#include "private_dir.hpp"
#include "readers.hpp"  // engine/io: load_from_memory

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

namespace sdfkit::fuzz {

// A path inside an empty private directory: a glTF's relative references resolve there (and
// find nothing), so a run never reads the machine's files.
inline const std::string& input_path(const char* extension) {
  static const std::string path = private_dir("/tmp/sdfkit-fuzz-XXXXXX") + "/input" + extension;
  return path;
}

inline int load_one(const std::uint8_t* data, std::size_t size, io::Format format,
                    const char* extension) {
  io::LoadOptions options;
  // Small limits keep each input fast; they are exercised like the defaults.
  options.max_triangles = 1u << 20;
  options.max_file_size = 1u << 24;
  try {
    const io::Asset asset = io::detail::load_from_memory(
        input_path(extension), format,
        std::string_view(reinterpret_cast<const char*>(data), size), options);
    // Every triangle index names a vertex (what load_asset promises its callers).
    for (const Triangle& t : asset.mesh.triangles)
      for (std::uint32_t v : t)
        if (v >= asset.mesh.positions.size()) std::abort();
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace sdfkit::fuzz

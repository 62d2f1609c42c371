#pragma once
// Internal to sdfkit_io: the per-format writers. Each receives the values already mapped to
// the input's order (one per input vertex, or one per input triangle) and writes to a stream;
// write_field wraps them in write_file_atomically.

#include "sdfkit/io/asset.hpp"

#include <iosfwd>
#include <span>
#include <string>
#include <vector>

namespace sdfkit::io::detail {

// The field as the writers need it, in input order.
struct OutputValues {
  SdfDomain domain = SdfDomain::Vertex;
  std::vector<float> raw;         // model units
  std::vector<float> normalized;  // [0,1]
};

void write_txt(std::ostream& out, const OutputValues& values, bool normalized);
// `positions` and `triangles`: the input's (asset.input_*), or the mesh where the asset's input
// is its mesh (see write_field).
void write_ply(std::ostream& out, std::span<const glm::vec3> positions, std::span<const Triangle> triangles,
               const OutputValues& values,
               const WriteOptions& options);
// Per-vertex values only. `binary` = .glb. Warnings (a replaced COLOR_0) go to `warnings`.
void write_gltf(std::ostream& out, bool binary, const Asset& asset, const OutputValues& values,
                const WriteOptions& options, std::vector<std::string>& warnings);

}  // namespace sdfkit::io::detail

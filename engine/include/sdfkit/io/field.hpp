#pragma once
// Reading SDF results back: the values sdfkit's writers stored (glTF/glb `_SDF`, PLY `quality`,
// .txt one value per line) next to the mesh they belong to, for `sdfkit render`, `compare` and
// `smooth`. Errors are InputError with one line "<path>: <problem>".

#include "sdfkit/io/asset.hpp"

#include <span>
#include <string>
#include <vector>

namespace sdfkit::io {

// A result file: the mesh as load_asset reads it, and its values in input order.
struct FieldFile {
  Asset asset;
  SdfDomain domain = SdfDomain::Vertex;
  // One per input vertex (domain Vertex: asset.input_positions order) or one per input
  // triangle (domain Face: asset.input_triangles order); model units as written (or [0,1] for
  // files written with --normalize). Empty when the file holds no values and they were optional.
  std::vector<float> values;
};

enum class ValuesRequired { Yes, No };

// Loads a mesh file with its stored values:
//  - .gltf/.glb: the `_SDF` attribute (FLOAT SCALAR) of every triangle primitive, per vertex;
//  - .ply: the `quality` property of the vertices (preferred) or of the faces;
//  - .obj/.off hold no values.
// With ValuesRequired::Yes a file without values is an InputError ("... has no _SDF attribute
// (not an sdfkit result?)"); with No it loads as a plain mesh with empty `values`. A .txt path
// is an InputError (values without a mesh: use read_values_txt with the mesh).
FieldFile read_field(const std::string& path, ValuesRequired required = ValuesRequired::Yes,
                     const LoadOptions& options = {});

// The values of a .txt result: one number per line (blank lines and surrounding spaces
// ignored). A line that is not one finite-or-not number is an InputError
// "<path>: line N: '<text>' is not a number".
std::vector<float> read_values_txt(const std::string& path);

// Values in input order (per input vertex or per input triangle) as values on asset.mesh: per
// welded vertex the value of the first input vertex welded into it; per-face values keep their
// order. Throws InputError when the count fits neither the input vertices nor the triangles.
std::vector<float> welded_values(const Asset& asset, SdfDomain domain,
                                 std::span<const float> input_values);

// The domain a plain list of `count` values has on `asset`: Vertex when it matches the input
// vertex count, Face when it matches the triangle count (vertices win a tie). Throws InputError
// naming `what` (a path) otherwise.
SdfDomain domain_of_count(const Asset& asset, std::size_t count, const std::string& what);

}  // namespace sdfkit::io

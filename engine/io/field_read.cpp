// Reading results back: `_SDF` from glTF/glb, `quality` from PLY, one value per line from .txt,
// and the map from input-order values to the welded mesh.

#include "sdfkit/io/field.hpp"

#include "gltf_model.hpp"
#include "readers.hpp"

#include <charconv>
#include <cstring>
#include <fstream>

namespace sdfkit::io {
namespace {

using detail::fail;

// The `count` floats of a FLOAT SCALAR accessor (tightly packed or strided), bounds-checked.
std::vector<float> read_float_accessor(const std::string& path, const tinygltf::Model& model,
                                       int index, const char* what) {
  if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size())
    fail(path, std::string(what) + " refers to a missing accessor");
  const tinygltf::Accessor& a = model.accessors[static_cast<std::size_t>(index)];
  if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || a.type != TINYGLTF_TYPE_SCALAR)
    fail(path, std::string(what) + " is not a FLOAT SCALAR accessor");
  if (a.sparse.isSparse) fail(path, std::string(what) + " is a sparse accessor (not supported)");
  std::vector<float> out(a.count, 0.0f);
  if (a.bufferView < 0) return out;  // all zeros by the glTF rules
  if (static_cast<std::size_t>(a.bufferView) >= model.bufferViews.size())
    fail(path, std::string(what) + " refers to a missing buffer view");
  const tinygltf::BufferView& v = model.bufferViews[static_cast<std::size_t>(a.bufferView)];
  if (v.buffer < 0 || static_cast<std::size_t>(v.buffer) >= model.buffers.size())
    fail(path, std::string(what) + " refers to a missing buffer");
  const std::vector<unsigned char>& data = model.buffers[static_cast<std::size_t>(v.buffer)].data;
  const std::size_t stride = v.byteStride ? v.byteStride : sizeof(float);
  const std::size_t start = v.byteOffset + a.byteOffset;
  const std::size_t view_end = v.byteOffset + v.byteLength;
  if (a.count > 0 &&
      (view_end > data.size() || start + (a.count - 1) * stride + sizeof(float) > view_end))
    fail(path, std::string(what) + " reaches past the end of its buffer");
  for (std::size_t i = 0; i < a.count; ++i)
    std::memcpy(&out[i], data.data() + start + i * stride, sizeof(float));
  return out;
}

// Per input vertex, from the `_SDF` attribute of every drawn triangle primitive.
std::vector<float> gltf_values(const Asset& asset, ValuesRequired required) {
  const auto* source = static_cast<const detail::GltfSource*>(asset.source.get());
  if (!source) fail(asset.path, "the glTF model was not kept while loading");
  std::vector<float> values(asset.input_positions.size(), 0.0f);
  for (const detail::GltfPrimitiveInstance& inst : source->instances) {
    const tinygltf::Primitive& prim =
        source->model.meshes[static_cast<std::size_t>(inst.mesh)]
            .primitives[static_cast<std::size_t>(inst.primitive)];
    const auto it = prim.attributes.find("_SDF");
    if (it == prim.attributes.end()) {
      if (required == ValuesRequired::No) return {};
      fail(asset.path, "mesh " + std::to_string(inst.mesh) + " primitive " +
                           std::to_string(inst.primitive) +
                           " has no _SDF attribute (not an sdfkit result?)");
    }
    const std::vector<float> v =
        read_float_accessor(asset.path, source->model, it->second, "the _SDF attribute");
    if (v.size() != inst.vertex_count)
      fail(asset.path, "the _SDF attribute of mesh " + std::to_string(inst.mesh) + " has " +
                           std::to_string(v.size()) + " values for " +
                           std::to_string(inst.vertex_count) + " vertices");
    std::copy(v.begin(), v.end(), values.begin() + inst.first_vertex);
  }
  return values;
}

}  // namespace

FieldFile read_field(const std::string& path, ValuesRequired required, const LoadOptions& options) {
  const Format format = format_from_path(path);
  if (format == Format::Txt)
    fail(path, "a .txt file holds values without a mesh; give the mesh as well");
  FieldFile f;
  f.asset = load_asset(path, options);
  switch (format) {
    case Format::Gltf:
    case Format::Glb: f.values = gltf_values(f.asset, required); break;
    case Format::Ply: {
      // The PLY reader keeps `quality`; read the file again for it (load_asset keeps only the
      // mesh).
      detail::RawMesh raw = detail::read_ply(path, detail::read_file(path, options.max_file_size));
      if (!raw.vertex_quality.empty()) {
        f.values = std::move(raw.vertex_quality);
      } else if (!raw.face_quality.empty()) {
        f.domain = SdfDomain::Face;
        f.values = std::move(raw.face_quality);
      } else if (required == ValuesRequired::Yes) {
        fail(path, "has no 'quality' property on its vertices or faces (not an sdfkit result?)");
      }
      break;
    }
    default:
      if (required == ValuesRequired::Yes)
        fail(path, std::string("a .") + format_name(format) +
                       " file holds no values (results are .glb, .gltf, .ply or .txt)");
  }
  return f;
}

std::vector<float> read_values_txt(const std::string& path) {
  const detail::FileData file = detail::read_file(path);
  const std::string_view data = file.view();
  std::vector<float> values;
  std::size_t line_no = 0, pos = 0;
  while (pos < data.size()) {
    std::size_t end = data.find('\n', pos);
    if (end == std::string_view::npos) end = data.size();
    ++line_no;
    std::string_view line(data.data() + pos, end - pos);
    pos = end + 1;
    const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
    while (!line.empty() && blank(line.front())) line.remove_prefix(1);
    while (!line.empty() && blank(line.back())) line.remove_suffix(1);
    if (line.empty()) continue;
    float v = 0.0f;
    const char* first = line.data();
    if (*first == '+') ++first;
    const auto [ptr, ec] = std::from_chars(first, line.data() + line.size(), v);
    if (ec != std::errc() || ptr != line.data() + line.size()) {
      std::string shown(line.substr(0, 40));
      for (char& c : shown)
        if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
      fail(path, "line " + std::to_string(line_no) + ": '" + shown + "' is not a number");
    }
    values.push_back(v);
  }
  return values;
}

std::vector<float> welded_values(const Asset& asset, SdfDomain domain,
                                 std::span<const float> input_values) {
  if (domain == SdfDomain::Face) {
    if (input_values.size() != asset.mesh.face_count())
      fail(asset.path, std::to_string(input_values.size()) + " per-face values for " +
                           std::to_string(asset.mesh.face_count()) + " faces");
    return {input_values.begin(), input_values.end()};
  }
  if (input_values.size() != asset.input_to_welded.size())
    fail(asset.path, std::to_string(input_values.size()) + " per-vertex values for " +
                         std::to_string(asset.input_to_welded.size()) + " vertices");
  std::vector<float> out(asset.mesh.vertex_count(), 0.0f);
  std::vector<char> set(out.size(), 0);
  for (std::size_t i = 0; i < input_values.size(); ++i) {
    const std::uint32_t w = asset.input_to_welded[i];
    if (!set[w]) {
      out[w] = input_values[i];
      set[w] = 1;
    }
  }
  return out;
}

SdfDomain domain_of_count(const Asset& asset, std::size_t count, const std::string& what) {
  if (count == asset.input_positions.size()) return SdfDomain::Vertex;
  if (count == asset.input_triangles.size()) return SdfDomain::Face;
  fail(what, "holds " + std::to_string(count) + " values but the mesh " + asset.path + " has " +
                 std::to_string(asset.input_positions.size()) + " vertices and " +
                 std::to_string(asset.input_triangles.size()) + " faces");
}

}  // namespace sdfkit::io

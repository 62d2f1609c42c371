// glTF/glb writer: the input glTF written back with _SDF, _SDF_NORMALIZED and COLOR_0 on every
// drawn triangle primitive, or a fresh minimal glTF for other inputs.
//
// Buffers: the output has a single buffer (all input buffers concatenated, 8-byte aligned, the
// new data appended), stored as the BIN chunk of a .glb or as a base64 data URI in a .gltf, so
// either output is one self-contained file. Images that were files or data URIs in the input
// move into bufferViews of a .glb, or become data URIs in a .gltf; images already inside a
// bufferView stay there; an image file that could not be read keeps its uri.

#include "gltf_model.hpp"
#include "writers.hpp"

#include "sdfkit/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <cctype>
#include <cstring>
#include <map>
#include <tuple>
#include <ostream>
#include <utility>

namespace sdfkit::io::detail {
namespace {

std::string base64(const std::vector<unsigned char>& bytes) {
  static constexpr char kTable[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const std::uint32_t v = (bytes[i] << 16) | (bytes[i + 1] << 8) | bytes[i + 2];
    out += kTable[(v >> 18) & 63];
    out += kTable[(v >> 12) & 63];
    out += kTable[(v >> 6) & 63];
    out += kTable[v & 63];
  }
  if (i < bytes.size()) {
    const std::uint32_t v = (bytes[i] << 16) | (i + 1 < bytes.size() ? bytes[i + 1] << 8 : 0);
    out += kTable[(v >> 18) & 63];
    out += kTable[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kTable[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string mime_for(const tinygltf::Image& image, const std::string& filename) {
  if (!image.mimeType.empty()) return image.mimeType;
  std::string ext = filename.substr(filename.find_last_of('.') + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  if (ext == "png") return "image/png";
  if (ext == "jpg" || ext == "jpeg") return "image/jpeg";
  if (ext == "bmp") return "image/bmp";
  if (ext == "gif") return "image/gif";
  return "application/octet-stream";
}

// tinygltf image writer: embeds the encoded bytes kept by keep_image_bytes as a data URI;
// images whose bytes could not be loaded keep their original uri.
bool embed_image(const std::string*, const std::string* filename, const tinygltf::Image* image,
                 bool, std::string* out_uri, void*) {
  if (image->image.empty()) return false;
  *out_uri = "data:" + mime_for(*image, filename ? *filename : std::string()) + ";base64," +
             base64(image->image);
  return true;
}

// Appends float data as a new bufferView + accessor of buffer 0; returns the accessor index.
class BufferAppender {
public:
  explicit BufferAppender(tinygltf::Model& model) : m_(model) {}

  int add_floats(const float* data, std::size_t count, int type, int target, bool min_max) {
    const int comps = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(type));
    return add(data, count, comps, TINYGLTF_COMPONENT_TYPE_FLOAT, type, target, min_max);
  }

  int add_indices(const std::uint32_t* data, std::size_t count) {
    return add(data, count, 1, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
               TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, false);
  }

  // Appends raw bytes (an encoded image) as a bufferView without target; returns its index.
  int add_view(const std::vector<unsigned char>& data) {
    std::vector<unsigned char>& bytes = m_.buffers[0].data;
    bytes.resize((bytes.size() + 7) / 8 * 8, 0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = bytes.size();
    view.byteLength = data.size();
    bytes.insert(bytes.end(), data.begin(), data.end());
    m_.bufferViews.push_back(view);
    return static_cast<int>(m_.bufferViews.size() - 1);
  }

private:
  template <typename T>
  int add(const T* data, std::size_t count, int comps, int component_type, int type, int target,
          bool min_max) {
    std::vector<unsigned char>& bytes = m_.buffers[0].data;
    bytes.resize((bytes.size() + 7) / 8 * 8, 0);  // 8-byte aligned views
    const std::size_t offset = bytes.size();
    const std::size_t length = count * static_cast<std::size_t>(comps) * sizeof(T);
    bytes.resize(offset + length);
    if (length > 0) std::memcpy(bytes.data() + offset, data, length);

    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = offset;
    view.byteLength = length;
    view.target = target;
    m_.bufferViews.push_back(view);

    tinygltf::Accessor a;
    a.bufferView = static_cast<int>(m_.bufferViews.size() - 1);
    a.byteOffset = 0;
    a.componentType = component_type;
    a.count = count;
    a.type = type;
    if (min_max && count > 0) {
      a.minValues.assign(static_cast<std::size_t>(comps), 0.0);
      a.maxValues.assign(static_cast<std::size_t>(comps), 0.0);
      for (int k = 0; k < comps; ++k) {
        double lo = static_cast<double>(data[k]), hi = lo;
        for (std::size_t i = 1; i < count; ++i) {
          const double v = static_cast<double>(
              data[i * static_cast<std::size_t>(comps) + static_cast<std::size_t>(k)]);
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
        a.minValues[static_cast<std::size_t>(k)] = lo;
        a.maxValues[static_cast<std::size_t>(k)] = hi;
      }
    }
    m_.accessors.push_back(a);
    return static_cast<int>(m_.accessors.size() - 1);
  }

  tinygltf::Model& m_;
};

// All buffers become buffer 0 (no uri): the BIN chunk of a glb or one data URI in a .gltf.
void merge_buffers(tinygltf::Model& model) {
  if (model.buffers.empty()) {
    model.buffers.emplace_back();
    return;
  }
  std::vector<std::size_t> base(model.buffers.size());
  tinygltf::Buffer merged;
  merged.name = model.buffers[0].name;
  for (std::size_t b = 0; b < model.buffers.size(); ++b) {
    merged.data.resize((merged.data.size() + 7) / 8 * 8, 0);
    base[b] = merged.data.size();
    merged.data.insert(merged.data.end(), model.buffers[b].data.begin(),
                       model.buffers[b].data.end());
  }
  for (tinygltf::BufferView& v : model.bufferViews) {
    if (v.buffer >= 0 && static_cast<std::size_t>(v.buffer) < base.size()) {
      v.byteOffset += base[static_cast<std::size_t>(v.buffer)];
      v.buffer = 0;
    }
  }
  model.buffers.assign(1, std::move(merged));
}

// Per-vertex data of one primitive instance: the values and their colours.
struct PrimitiveData {
  std::vector<float> raw, norm, rgb;
};

PrimitiveData slice(const OutputValues& values, std::uint32_t first, std::uint32_t count,
                    bool color) {
  PrimitiveData d;
  d.raw.assign(values.raw.begin() + first, values.raw.begin() + first + count);
  d.norm.assign(values.normalized.begin() + first, values.normalized.begin() + first + count);
  if (color) {
    d.rgb.resize(static_cast<std::size_t>(count) * 3);
    for (std::size_t i = 0; i < count; ++i) {
      const glm::vec3 c = colormap(d.norm[i]);
      d.rgb[3 * i] = c.x;
      d.rgb[3 * i + 1] = c.y;
      d.rgb[3 * i + 2] = c.z;
    }
  }
  return d;
}

void add_sdf_attributes(BufferAppender& appender, tinygltf::Primitive& prim, const PrimitiveData& d,
                        std::size_t count) {
  prim.attributes["_SDF"] = appender.add_floats(d.raw.data(), count, TINYGLTF_TYPE_SCALAR,
                                                TINYGLTF_TARGET_ARRAY_BUFFER, true);
  prim.attributes["_SDF_NORMALIZED"] = appender.add_floats(
      d.norm.data(), count, TINYGLTF_TYPE_SCALAR, TINYGLTF_TARGET_ARRAY_BUFFER, true);
  if (!d.rgb.empty())
    prim.attributes["COLOR_0"] = appender.add_floats(d.rgb.data(), count, TINYGLTF_TYPE_VEC3,
                                                     TINYGLTF_TARGET_ARRAY_BUFFER, false);
}

// For a .glb: images kept as encoded bytes (files or data URIs in the input) move into
// bufferViews of the BIN chunk, where glTF wants a binary container's images.
void move_images_into_buffer(tinygltf::Model& model, BufferAppender& appender) {
  for (tinygltf::Image& image : model.images) {
    if (image.bufferView >= 0 || image.image.empty()) continue;
    const std::string mime = mime_for(image, image.uri);
    if (mime.rfind("image/", 0) != 0) continue;  // stays a data URI
    image.mimeType = mime;
    image.bufferView = appender.add_view(image.image);
    image.uri.clear();
    image.image.clear();
  }
}

tinygltf::Model write_back_model(const GltfSource& src, bool binary, const OutputValues& values,
                                 const WriteOptions& options, std::vector<std::string>& warnings) {
  tinygltf::Model model = src.model;
  merge_buffers(model);
  BufferAppender appender(model);
  if (binary) move_images_into_buffer(model, appender);
  // The drawn meshes: a node's primitives one after the other. A mesh carries the values of
  // the first node that draws it; a node whose values differ (another scale, a transform that
  // is no similarity) draws a copy of the mesh with its own values (same POSITION, indices and
  // materials), one copy per distinct set of values.
  struct Draw {
    int node = -1, mesh = -1;
    std::vector<const GltfPrimitiveInstance*> prims;
  };
  std::vector<Draw> draws;
  for (const GltfPrimitiveInstance& inst : src.instances) {
    if (draws.empty() || draws.back().node != inst.node) draws.push_back({inst.node, inst.mesh, {}});
    draws.back().prims.push_back(&inst);
  }
  const auto same_values = [&](const Draw& a, const Draw& b) {
    if (a.prims.size() != b.prims.size()) return false;
    for (std::size_t p = 0; p < a.prims.size(); ++p) {
      if (a.prims[p]->vertex_count != b.prims[p]->vertex_count) return false;
      for (std::uint32_t k = 0; k < a.prims[p]->vertex_count; ++k) {
        const float x = values.raw[a.prims[p]->first_vertex + k], y = values.raw[b.prims[p]->first_vertex + k];
        if (std::abs(x - y) > 1e-5f * std::max({1.0f, std::abs(x), std::abs(y)})) return false;
      }
    }
    return true;
  };
  std::map<int, std::vector<std::pair<int, const Draw*>>> variants;  // mesh: (output mesh, values)
  std::size_t replaced_colors = 0;
  for (const Draw& d : draws) {
    auto& list = variants[d.mesh];
    int target = -1;
    for (const auto& [index, other] : list)
      if (same_values(d, *other)) target = index;
    if (target < 0) {
      target = list.empty() ? d.mesh : static_cast<int>(model.meshes.size());
      if (target != d.mesh) {
        model.meshes.push_back(src.model.meshes[static_cast<std::size_t>(d.mesh)]);
        model.meshes.back().name += model.meshes.back().name.empty() ? "sdf instance" : " (sdf instance)";
      }
      list.push_back({target, &d});
      for (const GltfPrimitiveInstance* inst : d.prims) {
        tinygltf::Primitive& prim = model.meshes[static_cast<std::size_t>(target)]
                                        .primitives[static_cast<std::size_t>(inst->primitive)];
        if (options.color && prim.attributes.count("COLOR_0")) ++replaced_colors;
        add_sdf_attributes(appender, prim,
                           slice(values, inst->first_vertex, inst->vertex_count, options.color),
                           inst->vertex_count);
      }
    }
    if (target != d.mesh) model.nodes[static_cast<std::size_t>(d.node)].mesh = target;
  }
  if (replaced_colors > 0)
    warnings.push_back("replaced the existing COLOR_0 of " + std::to_string(replaced_colors) +
                       " primitives with the SDF colours");
  return model;
}

// With a TEXCOORD_1 per triangle corner: one output vertex per (input vertex, UV) pair, in order
// of first use (input vertices no triangle uses keep one vertex with UV (0, 0)); `source` maps
// each output vertex to its input vertex.
struct SplitVertices {
  std::vector<std::uint32_t> source;
  std::vector<glm::vec2> uv;
  std::vector<Triangle> triangles;
};

SplitVertices split_by_corner_uv(const Asset& asset, const std::vector<std::array<glm::vec2, 3>>& corner_uv) {
  SplitVertices out;
  std::map<std::tuple<std::uint32_t, float, float>, std::uint32_t> index;
  std::vector<std::uint8_t> used(asset.input_positions.size(), 0);
  out.triangles.resize(asset.input_triangles.size());
  for (std::size_t f = 0; f < asset.input_triangles.size(); ++f)
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t v = asset.input_triangles[f][k];
      const glm::vec2 uv = corner_uv[f][k];
      const auto [it, added] = index.emplace(std::make_tuple(v, uv.x, uv.y), static_cast<std::uint32_t>(out.source.size()));
      if (added) out.source.push_back(v), out.uv.push_back(uv);
      out.triangles[f][k] = it->second;
      used[v] = 1;
    }
  for (std::uint32_t v = 0; v < used.size(); ++v)
    if (!used[v]) out.source.push_back(v), out.uv.push_back(glm::vec2(0.0f));
  return out;
}

tinygltf::Model fresh_model(const Asset& asset, const OutputValues& values,
                            const WriteOptions& options) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "sdfkit";
  model.buffers.emplace_back();
  BufferAppender appender(model);
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  if (!options.texcoord1.empty()) {
    const SplitVertices split = split_by_corner_uv(asset, options.texcoord1);
    const std::size_t nv = split.source.size();
    std::vector<glm::vec3> positions(nv);
    OutputValues copied;
    copied.raw.resize(nv);
    copied.normalized.resize(nv);
    for (std::size_t i = 0; i < nv; ++i) {
      positions[i] = asset.input_positions[split.source[i]];
      copied.raw[i] = values.raw[split.source[i]];
      copied.normalized[i] = values.normalized[split.source[i]];
    }
    prim.attributes["POSITION"] =
        appender.add_floats(&positions[0].x, nv, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
    // glTF numbers UV sets from 0 without gaps: a fresh asset has no set of its own, so
    // TEXCOORD_0 is the same accessor.
    prim.attributes["TEXCOORD_1"] =
        appender.add_floats(&split.uv[0].x, nv, TINYGLTF_TYPE_VEC2, TINYGLTF_TARGET_ARRAY_BUFFER, false);
    prim.attributes["TEXCOORD_0"] = prim.attributes["TEXCOORD_1"];
    prim.indices = appender.add_indices(split.triangles.data()->data(), split.triangles.size() * 3);
    add_sdf_attributes(appender, prim, slice(copied, 0, static_cast<std::uint32_t>(nv), options.color), nv);
  } else {
    const std::size_t nv = asset.input_positions.size();
    prim.attributes["POSITION"] = appender.add_floats(
        &asset.input_positions[0].x, nv, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
    prim.indices =
        appender.add_indices(asset.input_triangles.data()->data(), asset.input_triangles.size() * 3);
    add_sdf_attributes(appender, prim,
                       slice(values, 0, static_cast<std::uint32_t>(nv), options.color), nv);
  }
  tinygltf::Mesh mesh;
  mesh.primitives.push_back(std::move(prim));
  model.meshes.push_back(std::move(mesh));
  tinygltf::Node node;
  node.mesh = 0;
  model.nodes.push_back(std::move(node));
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  model.scenes.push_back(std::move(scene));
  model.defaultScene = 0;
  return model;
}

// Adds each overlay as a mesh (a LINES and a TRIANGLES primitive over one POSITION accessor)
// on a node of its own at the root of the default scene.
void add_overlays(tinygltf::Model& model, const std::vector<Overlay>& overlays) {
  if (overlays.empty()) return;
  if (model.buffers.empty()) model.buffers.emplace_back();
  BufferAppender appender(model);
  if (model.scenes.empty()) {
    model.scenes.emplace_back();
    model.defaultScene = 0;
  }
  const auto scene = static_cast<std::size_t>(model.defaultScene >= 0 ? model.defaultScene : 0);
  for (const Overlay& o : overlays) {
    if (o.points.empty() || (o.lines.empty() && o.triangles.empty())) continue;
    for (const auto& l : o.lines)
      if (l[0] >= o.points.size() || l[1] >= o.points.size())
        throw Error("overlay '" + o.name + "': a line uses a point index out of range");
    for (const auto& t : o.triangles)
      if (t[0] >= o.points.size() || t[1] >= o.points.size() || t[2] >= o.points.size())
        throw Error("overlay '" + o.name + "': a triangle uses a point index out of range");
    const int position = appender.add_floats(&o.points[0].x, o.points.size(), TINYGLTF_TYPE_VEC3,
                                             TINYGLTF_TARGET_ARRAY_BUFFER, true);
    tinygltf::Mesh mesh;
    mesh.name = o.name;
    // Marked so that sdfkit reading this file back takes only the surface.
    mesh.extras = tinygltf::Value(tinygltf::Value::Object{{"sdfkit_overlay", tinygltf::Value(true)}});
    if (!o.lines.empty()) {
      tinygltf::Primitive prim;
      prim.mode = TINYGLTF_MODE_LINE;
      prim.attributes["POSITION"] = position;
      prim.indices = appender.add_indices(o.lines.data()->data(), o.lines.size() * 2);
      mesh.primitives.push_back(std::move(prim));
    }
    if (!o.triangles.empty()) {
      tinygltf::Primitive prim;
      prim.mode = TINYGLTF_MODE_TRIANGLES;
      prim.attributes["POSITION"] = position;
      prim.indices = appender.add_indices(o.triangles.data()->data(), o.triangles.size() * 3);
      mesh.primitives.push_back(std::move(prim));
    }
    model.meshes.push_back(std::move(mesh));
    tinygltf::Node node;
    node.name = o.name;
    node.mesh = static_cast<int>(model.meshes.size() - 1);
    model.nodes.push_back(std::move(node));
    model.scenes[scene].nodes.push_back(static_cast<int>(model.nodes.size() - 1));
  }
}

}  // namespace

void write_gltf(std::ostream& out, bool binary, const Asset& asset, const OutputValues& values,
                const WriteOptions& options, std::vector<std::string>& warnings) {
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
  static_assert(sizeof(glm::vec2) == 2 * sizeof(float));
  static_assert(sizeof(Triangle) == 3 * sizeof(std::uint32_t));
  const auto* src = (asset.format == Format::Gltf || asset.format == Format::Glb)
                        ? static_cast<const GltfSource*>(asset.source.get())
                        : nullptr;
  if ((asset.format == Format::Gltf || asset.format == Format::Glb) && src == nullptr)
    throw Error(asset.path + ": the glTF asset has lost its source model");
  if (asset.input_positions.empty() || asset.input_triangles.empty())
    throw InputError(asset.path + ": the mesh has no triangles");
  tinygltf::Model model = src ? write_back_model(*src, binary, values, options, warnings)
                              : fresh_model(asset, values, options);
  add_overlays(model, options.overlays);
  tinygltf::TinyGLTF writer;
  writer.SetImageWriter(&embed_image, nullptr);
  if (!writer.WriteGltfSceneToStream(&model, out, /*prettyPrint=*/!binary, binary))
    throw Error(asset.path + ": tinygltf could not write the glTF output");
}

}  // namespace sdfkit::io::detail

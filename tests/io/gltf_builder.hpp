#pragma once
// Writes small glTF 2.0 files by hand (JSON text + binary blob) so the reader is tested against
// files that tinygltf did not write: .gltf with a data-URI or external buffer, and .glb.

#include "io_test_util.hpp"

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace sdfkit::test {

inline std::string base64_encode(const std::string& bytes) {
  static constexpr char kTable[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  auto byte = [&](std::size_t k) {
    return static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[k]));
  };
  for (; i + 2 < bytes.size(); i += 3) {
    const std::uint32_t v = (byte(i) << 16) | (byte(i + 1) << 8) | byte(i + 2);
    for (int s = 18; s >= 0; s -= 6) out += kTable[(v >> s) & 63];
  }
  if (i < bytes.size()) {
    const std::uint32_t v = (byte(i) << 16) | (i + 1 < bytes.size() ? byte(i + 1) << 8 : 0);
    out += kTable[(v >> 18) & 63];
    out += kTable[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kTable[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

class GltfBuilder {
public:
  // Appends raw bytes as a bufferView (4-byte aligned); returns its index.
  int view(const std::string& bytes, std::size_t stride = 0, int target = 0) {
    while (bin_.size() % 4) bin_ += '\0';
    std::string v = "{\"buffer\":0,\"byteOffset\":" + std::to_string(bin_.size()) +
                    ",\"byteLength\":" + std::to_string(bytes.size());
    if (stride) v += ",\"byteStride\":" + std::to_string(stride);
    if (target) v += ",\"target\":" + std::to_string(target);
    views_.push_back(v + "}");
    bin_ += bytes;
    return static_cast<int>(views_.size() - 1);
  }

  // An accessor on `view`; `extra` is appended inside the object (min/max, normalized, sparse).
  int accessor(int view_index, std::size_t offset, int component_type, std::size_t count,
               const std::string& type, const std::string& extra = "") {
    std::string a = "{";
    if (view_index >= 0) a += "\"bufferView\":" + std::to_string(view_index) + ",";
    a += "\"byteOffset\":" + std::to_string(offset) +
         ",\"componentType\":" + std::to_string(component_type) +
         ",\"count\":" + std::to_string(count) + ",\"type\":\"" + type + "\"" + extra + "}";
    accessors_.push_back(a);
    return static_cast<int>(accessors_.size() - 1);
  }

  // Tightly packed VEC3 float positions with min/max.
  int positions(const std::vector<float>& xyz) {
    std::string bytes;
    for (float f : xyz) put(bytes, f);
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (std::size_t i = 0; i < xyz.size(); ++i) {
      lo[i % 3] = std::min(lo[i % 3], xyz[i]);
      hi[i % 3] = std::max(hi[i % 3], xyz[i]);
    }
    auto arr = [](const float* v) {
      return "[" + std::to_string(v[0]) + "," + std::to_string(v[1]) + "," + std::to_string(v[2]) +
             "]";
    };
    return accessor(view(bytes, 0, 34962), 0, 5126, xyz.size() / 3, "VEC3",
                    ",\"min\":" + arr(lo) + ",\"max\":" + arr(hi));
  }

  template <typename T>
  int indices(const std::vector<T>& idx) {
    std::string bytes;
    for (T i : idx) put(bytes, i);
    const int ct = sizeof(T) == 1 ? 5121 : sizeof(T) == 2 ? 5123 : 5125;
    return accessor(view(bytes, 0, 34963), 0, ct, idx.size(), "SCALAR");
  }

  int mesh(const std::string& primitives_json) {
    meshes_.push_back("{\"primitives\":[" + primitives_json + "]}");
    return static_cast<int>(meshes_.size() - 1);
  }
  int node(const std::string& json) {
    nodes_.push_back(json);
    return static_cast<int>(nodes_.size() - 1);
  }
  // Extra top-level members ("\"materials\":[...]"), appended verbatim.
  void extra(const std::string& member) { extra_ += "," + member; }

  const std::string& bin() const { return bin_; }
  int last_view() const { return static_cast<int>(views_.size()) - 1; }

  // The JSON with the buffer given as `uri` (empty: no uri, for .glb); `scenes` is the scene
  // part ("\"scene\":0,\"scenes\":[{\"nodes\":[0]}]", or "" for none).
  std::string json(const std::string& uri, const std::string& scenes) const {
    std::string j = "{\"asset\":{\"version\":\"2.0\"}";
    if (!scenes.empty()) j += "," + scenes;
    j += ",\"nodes\":[" + join(nodes_) + "],\"meshes\":[" + join(meshes_) + "]";
    j += ",\"accessors\":[" + join(accessors_) + "],\"bufferViews\":[" + join(views_) + "]";
    j += ",\"buffers\":[{\"byteLength\":" + std::to_string(bin_.size());
    if (!uri.empty()) j += ",\"uri\":\"" + uri + "\"";
    j += "}]" + extra_ + "}";
    return j;
  }

  std::string data_uri_gltf(const std::string& scenes) const {
    return json("data:application/octet-stream;base64," + base64_encode(bin_), scenes);
  }

  std::string glb(const std::string& scenes) const {
    std::string j = json("", scenes);
    while (j.size() % 4) j += ' ';
    std::string b = bin_;
    while (b.size() % 4) b += '\0';
    std::string out = "glTF";
    put<std::uint32_t>(out, 2);
    put<std::uint32_t>(out, static_cast<std::uint32_t>(12 + 8 + j.size() + 8 + b.size()));
    put<std::uint32_t>(out, static_cast<std::uint32_t>(j.size()));
    put<std::uint32_t>(out, 0x4E4F534A);
    out += j;
    put<std::uint32_t>(out, static_cast<std::uint32_t>(b.size()));
    put<std::uint32_t>(out, 0x004E4942);
    out += b;
    return out;
  }

private:
  static std::string join(const std::vector<std::string>& parts) {
    std::string s;
    for (std::size_t i = 0; i < parts.size(); ++i) s += (i ? "," : "") + parts[i];
    return s;
  }

  std::string bin_;
  std::vector<std::string> views_, accessors_, meshes_, nodes_;
  std::string extra_;
};

}  // namespace sdfkit::test

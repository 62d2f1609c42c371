// glTF 2.0 reader (.gltf with external or data-URI buffers, .glb) through tinygltf. Every
// triangle primitive of the default scene (all root nodes when there is none) is placed by its
// node's world transform; the parsed model is kept for write-back.
//
// External files (buffers, images) go through ExternalFiles, tinygltf's file-system callbacks:
// by default a URI resolves only inside the asset's own directory (SECURITY.md).

#include "gltf_model.hpp"
#include "readers.hpp"

#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x4.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

namespace sdfkit::io::detail {

bool keep_image_bytes(tinygltf::Image* image, int, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void*) {
  // Images inside a bufferView stay in their buffer; others keep their encoded bytes so that
  // the writer can embed them.
  if (image->bufferView < 0 && bytes != nullptr && size > 0)
    image->image.assign(bytes, bytes + size);
  image->width = image->height = image->component = image->bits = -1;
  image->as_is = true;
  return true;
}

namespace {

namespace fs = std::filesystem;

// True when `uri` starts with a URI scheme (RFC 3986: ALPHA *( ALPHA / DIGIT / "+" / "-" / "." )
// then ':'), as in "http://...", "file:///..." or "C:/...".
bool has_scheme(const std::string& uri) {
  if (uri.empty() || !std::isalpha(static_cast<unsigned char>(uri[0]))) return false;
  for (std::size_t i = 1; i < uri.size(); ++i) {
    const auto c = static_cast<unsigned char>(uri[i]);
    if (c == ':') return true;
    if (!std::isalnum(c) && c != '+' && c != '-' && c != '.') return false;
  }
  return false;
}

// True when `p` is `root` or lies below it (both absolute and normal).
bool is_within(const fs::path& p, const fs::path& root) {
  auto r = root.begin();
  auto q = p.begin();
  for (; r != root.end(); ++r, ++q) {
    if (r->empty() && std::next(r) == root.end()) break;  // root's trailing separator
    if (q == p.end() || *q != *r) return false;
  }
  return true;
}

// tinygltf's file-system callbacks for one asset. tinygltf joins each external URI (percent-
// decoded) to the base directory it is given; we give it the asset's canonical directory, so the
// URI is what follows it. Confined (the default), a URI that is absolute, has a scheme, or
// resolves (`..`, symbolic links: weakly_canonical) outside that directory is refused before
// anything at its target is opened; the first refusal is kept for the error message, which is
// the same whatever the target is (nothing about it leaks). tinygltf's fallback of trying the
// URI against the working directory is never followed. Files past max_file_size are refused
// before they are read.
class ExternalFiles {
public:
  ExternalFiles(const std::string& asset_path, const LoadOptions& options)
      : allow_external_(options.allow_external_paths), max_size_(options.max_file_size) {
    std::error_code ec;
    fs::path dir = fs::absolute(fs::path(asset_path), ec).parent_path();
    if (!ec) root_ = fs::weakly_canonical(dir, ec);
    if (ec || root_.empty()) root_ = dir.lexically_normal();
    base_dir_ = root_.string();
    prefix_ = base_dir_.empty() || base_dir_.back() == '/' ? base_dir_ : base_dir_ + "/";
  }

  tinygltf::FsCallbacks callbacks() {
    return tinygltf::FsCallbacks{&ExternalFiles::exists, &ExternalFiles::expand,
                                 &ExternalFiles::read, &ExternalFiles::write, this};
  }
  const std::string& base_dir() const { return base_dir_; }
  // "external reference 'URI' ..." for the first refused or oversized file; "" if none.
  const std::string& problem() const { return problem_; }

private:
  // The file a joined path stands for, or nullopt (refused: problem_ says why).
  std::optional<fs::path> resolve(const std::string& joined) {
    if (joined.size() <= prefix_.size() || joined.compare(0, prefix_.size(), prefix_) != 0)
      return std::nullopt;  // tinygltf's working-directory fallback
    const std::string uri = joined.substr(prefix_.size());
    const fs::path as_path(uri);
    if (allow_external_) return as_path.is_absolute() ? as_path : root_ / as_path;
    // A NUL would cut the path the system sees short of the one checked here.
    if (uri.find('\0') != std::string::npos) return refuse(uri, "contains a NUL character");
    if (has_scheme(uri))
      return refuse(uri, "has a URI scheme (only data: URIs and relative paths are read)");
    if (as_path.is_absolute() || uri[0] == '/' || uri[0] == '\\')
      return refuse(uri, "is an absolute path");
    const fs::path relative = as_path.lexically_normal();
    if (relative.empty() || *relative.begin() == "..")
      return refuse(uri, "leaves the asset's directory");
    std::error_code ec;
    const fs::path resolved = fs::weakly_canonical(root_ / relative, ec);
    if (ec) return refuse(uri, "cannot be resolved");
    if (resolved == root_) return refuse(uri, "names the asset's directory, not a file");
    if (!is_within(resolved, root_))
      return refuse(uri, "leaves the asset's directory (through a symbolic link)");
    return resolved;
  }

  // The URI as the one-line message shows it: control characters as '?'.
  static std::string printable(const std::string& uri) {
    std::string out = uri.substr(0, 200);
    for (char& ch : out)
      if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ch = '?';
    return uri.size() > 200 ? out + "..." : out;
  }

  std::nullopt_t refuse(const std::string& uri, const std::string& why) {
    if (problem_.empty())
      problem_ = "external reference '" + printable(uri) + "' " + why +
                 "; refused: a glTF may read only files inside its own directory "
                 "(allow_external_paths, --allow-external-paths lifts this)";
    return std::nullopt;
  }

  static bool exists(const std::string& joined, void* self) {
    const std::optional<fs::path> p = static_cast<ExternalFiles*>(self)->resolve(joined);
    std::error_code ec;
    return p && fs::is_regular_file(*p, ec);
  }

  static std::string expand(const std::string& path, void*) { return path; }

  static bool read(std::vector<unsigned char>* out, std::string* err, const std::string& joined,
                   void* self_ptr) {
    auto* self = static_cast<ExternalFiles*>(self_ptr);
    const std::optional<fs::path> p = self->resolve(joined);
    if (!p) {
      if (err) *err = "refused";
      return false;
    }
    std::ifstream in(*p, std::ios::binary);
    if (!in) {
      if (err) *err = "cannot open the file";
      return false;
    }
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0) {
      if (err) *err = "cannot read the file size";
      return false;
    }
    if (self->max_size_ > 0 && static_cast<std::uint64_t>(size) > self->max_size_) {
      if (self->problem_.empty())
        self->problem_ = "external file '" + printable(joined.substr(self->prefix_.size())) +
                         "' has " + std::to_string(size) + " bytes, more than the limit of " +
                         std::to_string(self->max_size_) + " (max_file_size, --max-file-size)";
      if (err) *err = "too large";
      return false;
    }
    in.seekg(0, std::ios::beg);
    out->resize(static_cast<std::size_t>(size));
    if (size > 0 && !in.read(reinterpret_cast<char*>(out->data()), size)) {
      if (err) *err = "cannot read the file";
      return false;
    }
    return true;
  }

  static bool write(std::string* err, const std::string&, const std::vector<unsigned char>&,
                    void*) {
    if (err) *err = "sdfkit's glTF reader writes no files";
    return false;
  }

  bool allow_external_;
  std::uint64_t max_size_;
  fs::path root_;
  std::string base_dir_, prefix_;
  std::string problem_;
};

// First non-empty line of a tinygltf message, trimmed.
std::string first_line(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
    std::size_t b = 0;
    while (b < line.size() && std::isspace(static_cast<unsigned char>(line[b]))) ++b;
    if (b < line.size()) return line.substr(b);
  }
  return "";
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (!first_line(line).empty()) out.push_back(first_line(line));
  return out;
}

// Reads accessor data as numbers: the view of one accessor with every check a malformed file
// needs (indices in range, reads inside their buffers).
class AccessorReader {
public:
  AccessorReader(const std::string& path, const tinygltf::Model& model) : path_(path), m_(model) {}

  // `components` values per element, as floats (normalized integers mapped as the glTF spec
  // says, plain integers converted).
  std::vector<float> floats(int index, int components, const char* what) const {
    const tinygltf::Accessor& a = accessor(index, what);
    if (tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type)) != components)
      fail(path_, std::string(what) + " accessor " + std::to_string(index) +
                      " has the wrong type (expected " + std::to_string(components) +
                      " components)");
    std::vector<float> out;
    read_base(a, index, components, what, out);
    apply_sparse(a, index, components, what, out);
    return out;
  }

  // Vertex indices as uint32.
  std::vector<std::uint32_t> indices(int index) const {
    const tinygltf::Accessor& a = accessor(index, "index");
    if (a.type != TINYGLTF_TYPE_SCALAR ||
        (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
         a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
         a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
      fail(path_, "index accessor " + std::to_string(index) +
                      " is not a SCALAR of unsigned byte, short or int");
    std::vector<double> values;
    read_base(a, index, 1, "index", values);
    apply_sparse(a, index, 1, "index", values);
    std::vector<std::uint32_t> out(values.size());
    for (std::size_t i = 0; i < values.size(); ++i) out[i] = static_cast<std::uint32_t>(values[i]);
    return out;
  }

  const tinygltf::Accessor& accessor(int index, const char* what) const {
    if (index < 0 || static_cast<std::size_t>(index) >= m_.accessors.size())
      fail(path_, std::string(what) + " accessor " + std::to_string(index) + " does not exist");
    return m_.accessors[static_cast<std::size_t>(index)];
  }

private:
  static std::size_t component_size(int type) {
    const int s = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(type));
    return s > 0 ? static_cast<std::size_t>(s) : 0;
  }

  static double decode(const unsigned char* p, int type, bool normalized) {
    switch (type) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float v;
        std::memcpy(&v, p, 4);
        return v;
      }
      case TINYGLTF_COMPONENT_TYPE_DOUBLE: {
        double v;
        std::memcpy(&v, p, 8);
        return v;
      }
      case TINYGLTF_COMPONENT_TYPE_BYTE: {
        std::int8_t v;
        std::memcpy(&v, p, 1);
        return normalized ? std::max(v / 127.0, -1.0) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0 : p[0];
      case TINYGLTF_COMPONENT_TYPE_SHORT: {
        std::int16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? std::max(v / 32767.0, -1.0) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        std::uint16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? v / 65535.0 : v;
      }
      case TINYGLTF_COMPONENT_TYPE_INT: {
        std::int32_t v;
        std::memcpy(&v, p, 4);
        return v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        std::uint32_t v;
        std::memcpy(&v, p, 4);
        return normalized ? v / 4294967295.0 : v;
      }
      default: return 0.0;
    }
  }

  // The bytes of bufferView `view`, checked against its buffer.
  const unsigned char* view_bytes(int view, std::size_t& length, std::size_t& stride,
                                  int accessor_index, const char* what) const {
    if (view < 0 || static_cast<std::size_t>(view) >= m_.bufferViews.size())
      fail(path_, std::string(what) + " accessor " + std::to_string(accessor_index) +
                      " uses bufferView " + std::to_string(view) + " which does not exist");
    const tinygltf::BufferView& bv = m_.bufferViews[static_cast<std::size_t>(view)];
    if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= m_.buffers.size())
      fail(path_, "bufferView " + std::to_string(view) + " uses buffer " +
                      std::to_string(bv.buffer) + " which does not exist");
    const tinygltf::Buffer& b = m_.buffers[static_cast<std::size_t>(bv.buffer)];
    if (bv.byteOffset > b.data.size() || bv.byteLength > b.data.size() - bv.byteOffset)
      fail(path_, "bufferView " + std::to_string(view) + " reaches past the end of buffer " +
                      std::to_string(bv.buffer) + " (" + std::to_string(b.data.size()) +
                      " bytes loaded)");
    length = bv.byteLength;
    stride = bv.byteStride;
    return b.data.data() + bv.byteOffset;
  }

  // The accessor's own values (zeros without a bufferView, as the spec says), `out` resized
  // only after the declared count has been checked against the data.
  template <typename T>
  void read_base(const tinygltf::Accessor& a, int index, int components, const char* what,
                 std::vector<T>& out) const {
    if (a.bufferView >= 0) {
      read_into(a.bufferView, a.byteOffset, a.count, components, a.componentType, a.normalized,
                index, what, out);
      return;
    }
    if (!a.sparse.isSparse)
      fail(path_, std::string(what) + " accessor " + std::to_string(index) +
                      " has no data (no bufferView; compressed meshes are not supported)");
    // Sparse on zeros: the sparse part carries the data; bound the zeros by a sane size.
    if (a.count > (std::size_t{1} << 28))
      fail(path_, std::string(what) + " accessor " + std::to_string(index) +
                      " declares too many elements");
    out.assign(a.count * static_cast<std::size_t>(components), T(0));
  }

  template <typename T>
  void read_into(int view, std::size_t offset, std::size_t count, int components, int type,
                 bool normalized, int accessor_index, const char* what, std::vector<T>& out) const {
    const std::size_t csize = component_size(type);
    if (csize == 0)
      fail(path_, std::string(what) + " accessor " + std::to_string(accessor_index) +
                      " has an unknown component type " + std::to_string(type));
    std::size_t length = 0, stride = 0;
    const unsigned char* base = view_bytes(view, length, stride, accessor_index, what);
    const std::size_t element = csize * static_cast<std::size_t>(components);
    if (stride == 0) stride = element;
    if (stride < element)
      fail(path_, std::string(what) + " accessor " + std::to_string(accessor_index) +
                      " has a byteStride smaller than its element");
    if (count > 0 && (offset > length || element > length - offset ||
                      (count - 1) > (length - offset - element) / stride))
      fail(path_, std::string(what) + " accessor " + std::to_string(accessor_index) +
                      " reads past the end of bufferView " + std::to_string(view));
    out.resize(count * static_cast<std::size_t>(components));
    for (std::size_t i = 0; i < count; ++i) {
      const unsigned char* e = base + offset + i * stride;
      for (int k = 0; k < components; ++k)
        out[i * static_cast<std::size_t>(components) + static_cast<std::size_t>(k)] =
            static_cast<T>(decode(e + static_cast<std::size_t>(k) * csize, type, normalized));
    }
  }

  template <typename T>
  void apply_sparse(const tinygltf::Accessor& a, int index, int components, const char* what,
                    std::vector<T>& out) const {
    if (!a.sparse.isSparse) return;
    if (a.sparse.count < 0 || static_cast<std::size_t>(a.sparse.count) > a.count)
      fail(path_, std::string(what) + " accessor " + std::to_string(index) +
                      " has an invalid sparse count");
    const auto n = static_cast<std::size_t>(a.sparse.count);
    std::vector<double> where;
    read_into(a.sparse.indices.bufferView, static_cast<std::size_t>(a.sparse.indices.byteOffset), n,
              1, a.sparse.indices.componentType, false, index, what, where);
    std::vector<T> values;
    read_into(a.sparse.values.bufferView, static_cast<std::size_t>(a.sparse.values.byteOffset), n,
              components, a.componentType, a.normalized, index, what, values);
    for (std::size_t i = 0; i < n; ++i) {
      if (!(where[i] >= 0.0) || where[i] >= static_cast<double>(a.count))
        fail(path_, std::string(what) + " accessor " + std::to_string(index) +
                        " has a sparse index out of range");
      const auto target = static_cast<std::size_t>(where[i]);
      for (int k = 0; k < components; ++k)
        out[target * static_cast<std::size_t>(components) + static_cast<std::size_t>(k)] =
            values[i * static_cast<std::size_t>(components) + static_cast<std::size_t>(k)];
    }
  }

  const std::string& path_;
  const tinygltf::Model& m_;
};

// The node's local transform: its matrix, or translation * rotation * scale.
glm::dmat4 local_transform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    glm::dmat4 m;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[c][r] = node.matrix[static_cast<std::size_t>(c * 4 + r)];
    return m;
  }
  glm::dmat4 t(1.0), r(1.0), s(1.0);
  if (node.translation.size() == 3)
    t[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
  if (node.rotation.size() == 4) {
    const glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
    r = glm::mat4_cast(glm::normalize(q));
  }
  if (node.scale.size() == 3) {
    s[0][0] = node.scale[0];
    s[1][1] = node.scale[1];
    s[2][2] = node.scale[2];
  }
  return t * r * s;
}

const char* mode_name(int mode) {
  switch (mode) {
    case TINYGLTF_MODE_POINTS: return "POINTS";
    case TINYGLTF_MODE_LINE: return "LINES";
    case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP";
    case TINYGLTF_MODE_LINE_STRIP: return "LINE_STRIP";
    default: return "unknown-mode";
  }
}

// Walks the scene and appends every triangle primitive instance to the raw mesh.
class SceneWalker {
public:
  SceneWalker(const std::string& path, GltfSource& source, RawMesh& out)
      : path_(path), src_(source), m_(source.model), out_(out), reader_(path, source.model) {}

  void walk() {
    std::vector<int> roots;
    if (m_.defaultScene >= 0 && static_cast<std::size_t>(m_.defaultScene) < m_.scenes.size()) {
      roots = m_.scenes[static_cast<std::size_t>(m_.defaultScene)].nodes;
    } else {
      std::vector<std::uint8_t> is_child(m_.nodes.size(), 0);
      for (const tinygltf::Node& n : m_.nodes)
        for (int c : n.children)
          if (c >= 0 && static_cast<std::size_t>(c) < m_.nodes.size())
            is_child[static_cast<std::size_t>(c)] = 1;
      for (std::size_t i = 0; i < m_.nodes.size(); ++i)
        if (!is_child[i]) roots.push_back(static_cast<int>(i));
    }
    on_path_.assign(m_.nodes.size(), 0);
    for (int r : roots) visit(r, glm::dmat4(1.0));
    for (const auto& [what, count] : skipped_)
      out_.warnings.push_back("skipped " + std::to_string(count) + " " + what);
  }

private:
  void visit(int index, const glm::dmat4& parent) {
    if (index < 0 || static_cast<std::size_t>(index) >= m_.nodes.size())
      fail(path_, "the scene refers to node " + std::to_string(index) + " which does not exist");
    const auto i = static_cast<std::size_t>(index);
    if (on_path_[i]) fail(path_, "node " + std::to_string(index) + " is its own ancestor (cycle)");
    on_path_[i] = 1;
    const tinygltf::Node& node = m_.nodes[i];
    const glm::dmat4 world = parent * local_transform(node);
    if (node.mesh >= 0) {
      if (static_cast<std::size_t>(node.mesh) >= m_.meshes.size())
        fail(path_, "node " + std::to_string(index) + " uses mesh " + std::to_string(node.mesh) +
                        " which does not exist");
      const tinygltf::Mesh& mesh = m_.meshes[static_cast<std::size_t>(node.mesh)];
      if (is_overlay(mesh)) {
        ++skipped_["sdfkit overlays (" + mesh.name + ")"];
      } else {
        for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
          add_primitive(index, node.mesh, static_cast<int>(p), world);
      }
    }
    for (int c : node.children) visit(c, world);
    on_path_[i] = 0;
  }

  // Meshes sdfkit wrote as overlays (a skeleton) are not part of the surface.
  static bool is_overlay(const tinygltf::Mesh& mesh) {
    return mesh.extras.IsObject() && mesh.extras.Has("sdfkit_overlay") &&
           mesh.extras.Get("sdfkit_overlay").IsBool() && mesh.extras.Get("sdfkit_overlay").Get<bool>();
  }

  void add_primitive(int node, int mesh_index, int prim_index, const glm::dmat4& world) {
    const tinygltf::Primitive& prim = m_.meshes[static_cast<std::size_t>(mesh_index)]
                                          .primitives[static_cast<std::size_t>(prim_index)];
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      ++skipped_[std::string(mode_name(mode)) + " primitives"];
      return;
    }
    const auto pos_it = prim.attributes.find("POSITION");
    if (pos_it == prim.attributes.end()) {
      ++skipped_["triangle primitives without POSITION"];
      return;
    }
    const std::string where =
        "mesh " + std::to_string(mesh_index) + " primitive " + std::to_string(prim_index);
    // Limits before reading: a mesh drawn by many nodes is counted once per node.
    {
      const std::uint64_t vertices = reader_.accessor(pos_it->second, "POSITION").count;
      const std::uint64_t corners =
          prim.indices >= 0 ? reader_.accessor(prim.indices, "index").count : vertices;
      const std::uint64_t triangles = mode == TINYGLTF_MODE_TRIANGLES ? corners / 3
                                      : corners >= 2                  ? corners - 2
                                                                      : 0;
      check_vertex_count(path_, out_.positions.size() + vertices);
      check_triangle_count(path_, out_.triangles.size() + triangles);
    }
    const std::vector<float> xyz = reader_.floats(pos_it->second, 3, "POSITION");
    const std::size_t count = xyz.size() / 3;
    if (count == 0) {
      ++skipped_["triangle primitives without vertices"];
      return;
    }
    if (out_.positions.size() + count > UINT32_MAX) fail(path_, "too many vertices");
    const auto first = static_cast<std::uint32_t>(out_.positions.size());

    for (std::size_t v = 0; v < count; ++v) {
      const glm::dvec4 p = world * glm::dvec4(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2], 1.0);
      out_.positions.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y),
                                  static_cast<float>(p.z));
    }

    std::vector<std::uint32_t> idx;
    if (prim.indices >= 0) {
      idx = reader_.indices(prim.indices);
      for (std::uint32_t k : idx)
        if (k >= count)
          fail(path_, where + " uses vertex " + std::to_string(k) + " but its POSITION has " +
                          std::to_string(count) + " vertices");
    } else {
      idx.resize(count);
      for (std::size_t k = 0; k < count; ++k) idx[k] = static_cast<std::uint32_t>(k);
    }

    const auto first_triangle = static_cast<std::uint32_t>(out_.triangles.size());
    // A mirroring transform (negative determinant) flips the winding; glTF says to flip back.
    const bool flip = glm::determinant(glm::dmat3(world)) < 0.0;
    auto emit = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
      if (flip) std::swap(b, c);
      out_.triangles.push_back(Triangle{first + a, first + b, first + c});
    };
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      for (std::size_t t = 0; t + 2 < idx.size(); t += 3) emit(idx[t], idx[t + 1], idx[t + 2]);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (std::size_t t = 0; t + 2 < idx.size(); ++t) {
        if (t % 2 == 0)
          emit(idx[t], idx[t + 1], idx[t + 2]);
        else
          emit(idx[t + 1], idx[t], idx[t + 2]);
      }
    } else {
      for (std::size_t t = 1; t + 1 < idx.size(); ++t) emit(idx[t], idx[t + 1], idx[0]);
    }
    GltfPrimitiveInstance inst{node, mesh_index, prim_index, first, static_cast<std::uint32_t>(count),
                               first_triangle,
                               static_cast<std::uint32_t>(out_.triangles.size() - first_triangle), {}};
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) inst.world[static_cast<std::size_t>(4 * c + r)] = world[c][r];
    src_.instances.push_back(inst);
  }

  const std::string& path_;
  GltfSource& src_;
  const tinygltf::Model& m_;
  RawMesh& out_;
  AccessorReader reader_;
  std::vector<std::uint8_t> on_path_;
  std::map<std::string, std::size_t> skipped_;
};

// The GLB container's layout: every chunk (8-byte header and data) inside the length the header
// declares, and that length inside the file. tinygltf checks the BIN chunk's data against the
// length without its 8-byte header, so a BIN chunk could end up to 8 bytes past the file and its
// buffer be copied from there. Returns the problem, or "" (a file too short for a header is left
// to tinygltf, which says so).
std::string glb_layout_problem(std::string_view data) {
  if (data.size() < 12) return "";
  auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int b = 3; b >= 0; --b) v = (v << 8) | static_cast<unsigned char>(data[at + b]);
    return v;
  };
  const std::uint64_t length = u32(8);
  if (length > data.size())
    return "the GLB header says " + std::to_string(length) + " bytes but the file has " +
           std::to_string(data.size());
  std::uint64_t at = 12;
  for (int chunk = 0; at < length; ++chunk) {
    if (at + 8 > length)
      return "GLB chunk " + std::to_string(chunk) + "'s header reaches past the GLB's length";
    const std::uint64_t size = u32(static_cast<std::size_t>(at));
    if (at + 8 + size > length)
      return "GLB chunk " + std::to_string(chunk) + " (" + std::to_string(size) +
             " bytes) reaches past the GLB's length";
    at += 8 + size;
  }
  return "";
}

}  // namespace

RawMesh read_gltf(const std::string& path, std::string_view data, bool binary,
                  const LoadOptions& options) {
  auto source = std::make_shared<GltfSource>();
  ExternalFiles files(path, options);
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks(files.callbacks());
  loader.SetImageLoader(&keep_image_bytes, nullptr);
  loader.SetPreserveImageChannels(true);
  if (data.empty()) fail(path, "invalid glTF: the file is empty");
  if (data.size() > UINT32_MAX) fail(path, "invalid glTF: larger than 4 GiB");
  if (binary) {
    const std::string problem = glb_layout_problem(data);
    if (!problem.empty()) fail(path, "invalid glTF: " + problem);
  }
  std::string err, warn;
  const bool ok =
      binary ? loader.LoadBinaryFromMemory(&source->model, &err, &warn,
                                           reinterpret_cast<const unsigned char*>(data.data()),
                                           static_cast<unsigned int>(data.size()),
                                           files.base_dir())
             : loader.LoadASCIIFromString(&source->model, &err, &warn, data.data(),
                                          static_cast<unsigned int>(data.size()),
                                          files.base_dir());
  // A refused reference fails the load even where tinygltf only warns (images).
  if (!files.problem().empty()) fail(path, files.problem());
  if (!ok) {
    std::string problem = first_line(err);
    if (problem.empty()) problem = first_line(warn);
    if (problem.empty()) problem = "not a valid glTF file";
    fail(path, "invalid glTF: " + problem);
  }
  RawMesh out;
  for (const std::string& w : lines_of(warn)) out.warnings.push_back(w);
  for (const std::string& ext : source->model.extensionsRequired) {
    if (ext != "KHR_mesh_quantization" && ext != "KHR_materials_unlit" &&
        ext != "KHR_texture_transform")
      fail(path, "requires the glTF extension " + ext + ", which sdfkit cannot read");
  }
  SceneWalker(path, *source, out).walk();
  if (out.triangles.empty() && !source->instances.empty())
    fail(path, "the scene's triangle primitives have no triangles");
  if (source->instances.empty())
    fail(path, out.warnings.empty()
                   ? std::string("the scene has no triangle primitives")
                   : "the scene has no triangle primitives (" + out.warnings.back() + ")");
  out.source = std::move(source);
  return out;
}

}  // namespace sdfkit::io::detail

// Point-cloud input: PLY vertices, XYZ/CSV text, Sibernetic frame sets, directories and globs.

#include "sdfkit/pointcloud/pointcloud.hpp"

#include "sdfkit/core/error.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fnmatch.h>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace sdfkit::pointcloud {
namespace {

std::string lower_ext(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

bool is_cloud_file(const fs::path& p) {
  const std::string e = lower_ext(p);
  return e == ".ply" || e == ".xyz" || e == ".csv" || e == ".txt" || e == ".pts";
}

std::size_t ply_type_size(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

double ply_binary_value(const unsigned char* p, const std::string& t, bool big) {
  unsigned char b[8];
  const std::size_t s = ply_type_size(t);
  std::memcpy(b, p, s);
  if (big != (std::endian::native == std::endian::big)) std::reverse(b, b + s);
  if (t == "float" || t == "float32") { float v; std::memcpy(&v, b, 4); return v; }
  if (t == "double" || t == "float64") { double v; std::memcpy(&v, b, 8); return v; }
  if (t == "char" || t == "int8") return static_cast<std::int8_t>(b[0]);
  if (t == "uchar" || t == "uint8") return b[0];
  if (t == "short" || t == "int16") { std::int16_t v; std::memcpy(&v, b, 2); return v; }
  if (t == "ushort" || t == "uint16") { std::uint16_t v; std::memcpy(&v, b, 2); return v; }
  if (t == "int" || t == "int32") { std::int32_t v; std::memcpy(&v, b, 4); return v; }
  std::uint32_t v; std::memcpy(&v, b, 4); return v;
}

std::vector<glm::vec3> read_ply(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open " + path);
  std::string line;
  std::getline(in, line);
  if (line.rfind("ply", 0) != 0) throw InputError(path + ": not a PLY file");
  std::string format;
  std::size_t vertex_count = 0;
  bool in_vertex = false, vertex_first = true, seen_element = false;
  std::vector<std::pair<std::string, std::string>> props;  // (type, name) of the vertex element
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "format") ls >> format;
    else if (word == "element") {
      std::string name;
      std::size_t count = 0;
      ls >> name >> count;
      if (name == "vertex") {
        in_vertex = true;
        vertex_first = !seen_element;
        vertex_count = count;
      } else in_vertex = false;
      seen_element = true;
    } else if (word == "property" && in_vertex) {
      std::string type, name;
      ls >> type;
      if (type == "list") throw InputError(path + ": list properties on vertices are not supported");
      ls >> name;
      if (ply_type_size(type) == 0) throw InputError(path + ": unknown PLY property type '" + type + "'");
      props.emplace_back(type, name);
    } else if (word == "end_header") break;
  }
  if (!vertex_first) throw InputError(path + ": the vertex element must come first in the PLY file");
  int ix = -1, iy = -1, iz = -1;
  for (std::size_t p = 0; p < props.size(); ++p) {
    if (props[p].second == "x") ix = static_cast<int>(p);
    if (props[p].second == "y") iy = static_cast<int>(p);
    if (props[p].second == "z") iz = static_cast<int>(p);
  }
  if (ix < 0 || iy < 0 || iz < 0) throw InputError(path + ": PLY vertices need x, y and z");
  std::vector<glm::vec3> pts(vertex_count);
  if (format == "ascii") {
    std::vector<double> vals(props.size());
    for (std::size_t i = 0; i < vertex_count; ++i) {
      for (double& v : vals)
        if (!(in >> v)) throw InputError(path + ": PLY vertex data ends early");
      pts[i] = glm::vec3(vals[ix], vals[iy], vals[iz]);
    }
  } else if (format == "binary_little_endian" || format == "binary_big_endian") {
    const bool big = format == "binary_big_endian";
    std::size_t stride = 0;
    std::vector<std::size_t> offset(props.size());
    for (std::size_t p = 0; p < props.size(); ++p) {
      offset[p] = stride;
      stride += ply_type_size(props[p].first);
    }
    std::vector<unsigned char> buf(stride * vertex_count);
    in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(buf.size()));
    if (static_cast<std::size_t>(in.gcount()) != buf.size()) throw InputError(path + ": PLY vertex data ends early");
    for (std::size_t i = 0; i < vertex_count; ++i) {
      const unsigned char* row = buf.data() + i * stride;
      pts[i] = glm::vec3(ply_binary_value(row + offset[ix], props[ix].first, big),
                         ply_binary_value(row + offset[iy], props[iy].first, big),
                         ply_binary_value(row + offset[iz], props[iz].first, big));
    }
  } else {
    throw InputError(path + ": unknown PLY format '" + format + "'");
  }
  return pts;
}

std::vector<glm::vec3> read_text(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot open " + path);
  std::vector<glm::vec3> pts;
  std::string line;
  std::size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    for (char& c : line)
      if (c == ',' || c == ';' || c == '\t' || c == '\r') c = ' ';
    std::istringstream ls(line);
    double v[3];
    if (!(ls >> v[0])) {
      std::string rest;
      std::istringstream again(line);
      if (again >> rest && pts.empty() && number == 1) continue;  // a header line
      if (!(std::istringstream(line) >> rest)) continue;          // blank
      throw InputError(path + ":" + std::to_string(number) + ": expected three numbers");
    }
    if (!(ls >> v[1] >> v[2])) throw InputError(path + ":" + std::to_string(number) + ": expected three numbers");
    pts.emplace_back(v[0], v[1], v[2]);
  }
  return pts;
}

FrameSet read_sibernetic(const fs::path& dir, bool surface_only) {
  FrameSet set;
  std::ifstream pin(dir / "particles.txt");
  if (!pin) throw InputError(dir.string() + ": particles.txt is missing");
  std::vector<std::uint8_t> shell;
  std::string line;
  while (std::getline(pin, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    double index, type, cls, slice, sh;
    if (!(ls >> index >> type >> cls >> slice >> sh)) throw InputError(dir.string() + "/particles.txt: malformed line");
    shell.push_back(sh != 0.0 ? 1 : 0);
  }
  const std::size_t n = shell.size();
  if (n == 0) throw InputError(dir.string() + "/particles.txt lists no particles");
  const fs::path bin = dir / "positions_f32le.bin";
  std::ifstream in(bin, std::ios::binary);
  if (!in) throw InputError("cannot open " + bin.string());
  const auto bytes = fs::file_size(bin);
  if (bytes % (n * 12) != 0)
    throw InputError(bin.string() + ": size is not a whole number of frames of " + std::to_string(n) + " particles");
  const std::size_t frames = bytes / (n * 12);
  std::vector<float> buf(n * 3);
  for (std::size_t f = 0; f < frames; ++f) {
    in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(n * 12));
    std::vector<glm::vec3> pts;
    pts.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (surface_only && !shell[i]) continue;
      float v[3];
      for (int d = 0; d < 3; ++d) {
        v[d] = buf[3 * i + d];
        if constexpr (std::endian::native == std::endian::big) {
          std::uint32_t u;
          std::memcpy(&u, &v[d], 4);
          u = __builtin_bswap32(u);
          std::memcpy(&v[d], &u, 4);
        }
      }
      pts.emplace_back(v[0], v[1], v[2]);
    }
    set.frames.push_back(std::move(pts));
    set.names.push_back("frame " + std::to_string(f));
  }
  std::ifstream tin(dir / "frames.txt");
  std::vector<double> times;
  while (tin && std::getline(tin, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    double fr, it, t;
    if (ls >> fr >> it >> t) times.push_back(t);
  }
  if (times.size() >= 2) set.frame_time = times[1] - times[0];
  return set;
}

}  // namespace

std::vector<glm::vec3> read_point_cloud(const std::string& path) {
  if (!fs::is_regular_file(path)) throw InputError("cannot open " + path + " (not a file)");
  // Mesh formats other than PLY are not point clouds: read as text, an OFF header's counts or an OBJ's
  // face lines would pass for points.
  const std::string ext = lower_ext(path);
  if (ext == ".off" || ext == ".obj" || ext == ".stl" || ext == ".gltf" || ext == ".glb")
    throw InputError(path + ": a mesh file, not a point cloud (point clouds are .ply, .xyz, .csv, .txt or .pts)");
  std::vector<glm::vec3> pts = ext == ".ply" ? read_ply(path) : read_text(path);
  if (pts.empty()) throw InputError(path + ": no points");
  for (const glm::vec3& p : pts)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw InputError(path + ": a coordinate is not finite");
  return pts;
}

FrameSet read_frames(const std::string& source, bool surface_only) {
  FrameSet set;
  std::vector<fs::path> files;
  const fs::path src(source);
  if (fs::is_directory(src)) {
    if (fs::exists(src / "positions_f32le.bin")) return read_sibernetic(src, surface_only);
    for (const auto& e : fs::directory_iterator(src))
      if (e.is_regular_file() && is_cloud_file(e.path())) files.push_back(e.path());
    if (files.empty()) throw InputError(source + ": no .ply/.xyz/.csv/.txt point clouds in the directory");
  } else if (fs::is_regular_file(src)) {
    files.push_back(src);
  } else if (source.find_first_of("*?") != std::string::npos) {
    const fs::path dir = src.parent_path().empty() ? fs::path(".") : src.parent_path();
    const std::string pattern = src.filename().string();
    if (dir.string().find_first_of("*?") != std::string::npos)
      throw InputError(source + ": wildcards are only supported in the file name");
    if (fs::is_directory(dir))
      for (const auto& e : fs::directory_iterator(dir))
        if (e.is_regular_file() && fnmatch(pattern.c_str(), e.path().filename().c_str(), 0) == 0) files.push_back(e.path());
    if (files.empty()) throw InputError(source + ": no file matches");
  } else {
    throw InputError("cannot open " + source);
  }
  std::sort(files.begin(), files.end());
  for (const fs::path& f : files) {
    set.frames.push_back(read_point_cloud(f.string()));
    set.names.push_back(f.filename().string());
  }
  return set;
}

}  // namespace sdfkit::pointcloud

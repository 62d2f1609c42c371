// read_skeleton_json: a skeleton as `sdfkit skeleton` writes it (skeleton::to_json), read back
// for the skeleton texture mapping.
#include "sdfkit/diffusion/stm.hpp"

#include "sdfkit/core/error.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <sstream>

namespace sdfkit::diffusion {
namespace {

std::uint32_t index_of(const nlohmann::json& j, std::size_t limit, const std::string& what, const std::string& where) {
  if (!j.is_number_integer() || j.get<long long>() < 0 || static_cast<unsigned long long>(j.get<long long>()) >= limit)
    throw InputError(where + ": " + what + " is not an index below " + std::to_string(limit));
  return static_cast<std::uint32_t>(j.get<long long>());
}

}  // namespace

skeleton::Skeleton parse_skeleton_json(const std::string& text, const std::string& where) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(where + ": not valid JSON (" + std::string(e.what()) + ")");
  }
  if (!j.is_object() || !j.contains("nodes") || !j["nodes"].is_array())
    throw InputError(where + ": a skeleton is a JSON object with a \"nodes\" array");
  skeleton::Skeleton s;
  const std::size_t vertex_limit = std::size_t{1} << 32;
  for (std::size_t i = 0; i < j["nodes"].size(); ++i) {
    const nlohmann::json& n = j["nodes"][i];
    const std::string what = "node " + std::to_string(i);
    if (!n.is_object()) throw InputError(where + ": " + what + " is not an object");
    skeleton::Node node;
    const nlohmann::json* p = n.contains("position") ? &n["position"] : nullptr;
    if (!p || !p->is_array() || p->size() != 3 || !(*p)[0].is_number() || !(*p)[1].is_number() || !(*p)[2].is_number())
      throw InputError(where + ": " + what + " has no \"position\" of three numbers");
    node.position = {(*p)[0].get<float>(), (*p)[1].get<float>(), (*p)[2].get<float>()};
    if (!std::isfinite(node.position.x) || !std::isfinite(node.position.y) || !std::isfinite(node.position.z))
      throw InputError(where + ": " + what + " has a non-finite position");
    if (n.contains("radius")) {
      if (!n["radius"].is_number()) throw InputError(where + ": the radius of " + what + " is not a number");
      node.radius = n["radius"].get<float>();
    }
    if (n.contains("sheet")) {
      if (!n["sheet"].is_boolean()) throw InputError(where + ": \"sheet\" of " + what + " is not true or false");
      node.sheet = n["sheet"].get<bool>();
    }
    if (n.contains("vertices")) {
      if (!n["vertices"].is_array()) throw InputError(where + ": \"vertices\" of " + what + " is not an array");
      for (const nlohmann::json& v : n["vertices"]) node.vertices.push_back(index_of(v, vertex_limit, "a vertex of " + what, where));
    }
    s.nodes.push_back(std::move(node));
  }
  const std::size_t N = s.nodes.size();
  if (j.contains("edges")) {
    if (!j["edges"].is_array()) throw InputError(where + ": \"edges\" is not an array");
    for (std::size_t i = 0; i < j["edges"].size(); ++i) {
      const nlohmann::json& e = j["edges"][i];
      const std::string what = "edge " + std::to_string(i);
      if (!e.is_array() || e.size() != 2) throw InputError(where + ": " + what + " is not two node indices");
      s.edges.push_back({index_of(e[0], N, what, where), index_of(e[1], N, what, where)});
    }
  }
  if (j.contains("sheet_triangles")) {
    if (!j["sheet_triangles"].is_array()) throw InputError(where + ": \"sheet_triangles\" is not an array");
    for (std::size_t i = 0; i < j["sheet_triangles"].size(); ++i) {
      const nlohmann::json& t = j["sheet_triangles"][i];
      const std::string what = "sheet triangle " + std::to_string(i);
      if (!t.is_array() || t.size() != 3) throw InputError(where + ": " + what + " is not three node indices");
      s.sheet_triangles.push_back({index_of(t[0], N, what, where), index_of(t[1], N, what, where), index_of(t[2], N, what, where)});
    }
  }
  if (j.contains("reliability") && j["reliability"].is_number()) s.reliability = j["reliability"].get<double>();
  if (j.contains("curve_reliability") && j["curve_reliability"].is_number())
    s.curve_reliability = j["curve_reliability"].get<double>();
  return s;
}

skeleton::Skeleton read_skeleton_json(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the skeleton file");
  std::ostringstream text;
  text << in.rdbuf();
  if (!in.good() && !in.eof()) throw InputError(path + ": cannot read the skeleton file");
  return parse_skeleton_json(text.str(), path);
}

}  // namespace sdfkit::diffusion

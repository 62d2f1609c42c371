// Skeleton files for pictures: `sdfkit skeleton`'s JSON (nodes, edges, sheet_triangles) and
// `sdfkit pointcloud-skeleton`'s (an ordered polyline of nodes, or {"frames": [...]}).

#include "sdfkit/render/figure.hpp"

#include "sdfkit/core/error.hpp"

#include <nlohmann/json.hpp>

#include <fstream>

namespace sdfkit::render {
namespace {

glm::vec3 json_point(const nlohmann::json& j, const std::string& what) {
  if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
    throw InputError(what + " is not an array of three numbers");
  return {j[0].get<float>(), j[1].get<float>(), j[2].get<float>()};
}

SkeletonOverlay read_one(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object() || !j.contains("nodes"))
    throw InputError(where + "a skeleton is a JSON object with \"nodes\" (or \"frames\")");
  if (!j["nodes"].is_array()) throw InputError(where + "\"nodes\" is not an array");
  SkeletonOverlay s;
  for (std::size_t i = 0; i < j["nodes"].size(); ++i) {
    const nlohmann::json& n = j["nodes"][i];
    if (!n.is_object() || !n.contains("position"))
      throw InputError(where + "node " + std::to_string(i) + " has no \"position\"");
    s.nodes.push_back(json_point(n["position"], where + "the position of node " + std::to_string(i)));
  }
  const auto items = [&](const char* key, auto& out) {
    if (!j.contains(key)) return;
    if (!j[key].is_array()) throw InputError(where + "\"" + key + "\" is not an array");
    constexpr std::size_t arity = std::tuple_size_v<typename std::decay_t<decltype(out)>::value_type>;
    for (std::size_t i = 0; i < j[key].size(); ++i) {
      const nlohmann::json& e = j[key][i];
      const std::string what = where + key + " entry " + std::to_string(i);
      if (!e.is_array() || e.size() != arity)
        throw InputError(what + " is not " + std::to_string(arity) + " node indices");
      typename std::decay_t<decltype(out)>::value_type item{};
      for (std::size_t k = 0; k < arity; ++k) {
        if (!e[k].is_number_integer() || e[k].get<long long>() < 0 ||
            static_cast<std::size_t>(e[k].get<long long>()) >= s.nodes.size())
          throw InputError(what + " refers to a node that does not exist");
        item[k] = static_cast<std::uint32_t>(e[k].get<long long>());
      }
      out.push_back(item);
    }
  };
  items("edges", s.edges);
  items("sheet_triangles", s.sheet_triangles);
  if (!j.contains("edges") && !j.contains("sheet_triangles")) {
    // An ordered polyline: consecutive nodes joined, the first one marked.
    s.ordered = true;
    for (std::uint32_t i = 0; i + 1 < s.nodes.size(); ++i) s.edges.push_back({i, i + 1});
  }
  validate(s);
  return s;
}

}  // namespace

std::vector<SkeletonOverlay> read_skeleton_json(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the skeleton file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": not valid JSON (" + std::string(e.what()) + ")");
  }
  std::vector<SkeletonOverlay> frames;
  try {
    if (j.is_object() && j.contains("frames")) {
      if (!j["frames"].is_array() || j["frames"].empty())
        throw InputError("\"frames\" is not a non-empty array");
      for (std::size_t f = 0; f < j["frames"].size(); ++f)
        frames.push_back(read_one(j["frames"][f], "frame " + std::to_string(f) + ": "));
    } else {
      frames.push_back(read_one(j, ""));
    }
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
  return frames;
}

}  // namespace sdfkit::render

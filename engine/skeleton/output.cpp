#include "sdfkit/skeleton/skeleton.hpp"

#include "sdfkit/core/union_find.hpp"

#include <nlohmann/json.hpp>

#include <ostream>
#include <set>

namespace sdfkit::skeleton {

std::string to_json(const Skeleton& s) {
  nlohmann::json nodes = nlohmann::json::array();
  for (const Node& n : s.nodes)
    nodes.push_back({{"position", {n.position.x, n.position.y, n.position.z}},
                     {"radius", n.radius},
                     {"sheet", n.sheet},
                     {"vertices", n.vertices}});
  nlohmann::json j;
  j["nodes"] = std::move(nodes);
  j["edges"] = s.edges;
  j["sheet_triangles"] = s.sheet_triangles;
  j["reliability"] = s.reliability;
  j["curve_reliability"] = s.curve_reliability;
  j["iterations"] = s.iterations;
  j["warnings"] = s.warnings;
  return j.dump();
}

void write_obj(std::ostream& out, const Skeleton& s) {
  out << "# sdfkit skeleton: " << s.nodes.size() << " nodes, " << s.edges.size() << " edges, "
      << s.sheet_triangles.size() << " sheet triangles\n";
  for (const Node& n : s.nodes) out << "v " << n.position.x << ' ' << n.position.y << ' ' << n.position.z << '\n';
  for (const auto& e : s.edges) out << "l " << e[0] + 1 << ' ' << e[1] + 1 << '\n';
  for (const Triangle& t : s.sheet_triangles)
    out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
}

int cycle_count(const Skeleton& s) {
  // First Betti number of the 1- and 2-cells: E - V + components - F (sheets enclose no volume).
  const std::size_t v = s.nodes.size();
  std::set<std::array<std::uint32_t, 2>> edges(s.edges.begin(), s.edges.end());
  for (const Triangle& t : s.sheet_triangles)
    for (int i = 0; i < 3; ++i)
      edges.insert({std::min(t[i], t[(i + 1) % 3]), std::max(t[i], t[(i + 1) % 3])});
  UnionFind uf(v);
  std::size_t components = v;
  for (const auto& e : edges) components -= uf.unite(e[0], e[1]);
  return static_cast<int>(edges.size()) - static_cast<int>(v) + static_cast<int>(components) -
         static_cast<int>(s.sheet_triangles.size());
}

}  // namespace sdfkit::skeleton

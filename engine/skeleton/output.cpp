#include "sdfkit/skeleton/skeleton.hpp"

#include "sdfkit/core/union_find.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <functional>
#include <iterator>
#include <map>
#include <ostream>
#include <vector>

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
  // First Betti number over Z/2: dim ker(boundary of edges) - rank(boundary of triangles)
  // = (E - V + components) - rank. Triangles whose boundaries add up to zero (a closed sheet
  // around a void) do not lower it, so it never goes negative.
  const std::size_t v = s.nodes.size();
  std::map<std::array<std::uint32_t, 2>, std::uint32_t> edge_index;
  auto edge = [&](std::uint32_t a, std::uint32_t b) {
    const std::array<std::uint32_t, 2> key{std::min(a, b), std::max(a, b)};
    return edge_index.emplace(key, static_cast<std::uint32_t>(edge_index.size())).first->second;
  };
  for (const auto& e : s.edges) edge(e[0], e[1]);
  std::vector<std::vector<std::uint32_t>> columns;  // per sheet triangle: its edges, descending
  for (const Triangle& t : s.sheet_triangles) {
    std::vector<std::uint32_t> c{edge(t[0], t[1]), edge(t[1], t[2]), edge(t[2], t[0])};
    std::sort(c.begin(), c.end(), std::greater<>());
    c.erase(std::unique(c.begin(), c.end()), c.end());
    columns.push_back(std::move(c));
  }
  UnionFind uf(v);
  std::size_t components = v;
  for (const auto& [key, index] : edge_index) components -= uf.unite(key[0], key[1]);
  // Rank of the triangle-to-edge boundary matrix by column reduction: a column is reduced by
  // the column owning its largest edge until that edge is new (a pivot) or the column is empty.
  std::map<std::uint32_t, std::size_t> pivot_of;  // largest edge -> column
  std::size_t rank = 0;
  for (std::size_t k = 0; k < columns.size(); ++k) {
    std::vector<std::uint32_t>& c = columns[k];
    while (!c.empty()) {
      const auto owner = pivot_of.find(c.front());
      if (owner == pivot_of.end()) {
        pivot_of.emplace(c.front(), k);
        ++rank;
        break;
      }
      std::vector<std::uint32_t> sum;  // symmetric difference, still descending
      std::set_symmetric_difference(c.begin(), c.end(), columns[owner->second].begin(),
                                    columns[owner->second].end(), std::back_inserter(sum),
                                    std::greater<>());
      c = std::move(sum);
    }
  }
  return static_cast<int>(edge_index.size()) - static_cast<int>(v) + static_cast<int>(components) -
         static_cast<int>(rank);
}

}  // namespace sdfkit::skeleton

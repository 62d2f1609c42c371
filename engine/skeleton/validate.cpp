#include "validate.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/topology.hpp"
#include "sdfkit/core/union_find.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace sdfkit::skeleton::detail {

void require_closed(const Mesh& mesh, const std::string& what) {
  validate_mesh(mesh, what);
  const MeshReport r = analyze(mesh);
  if (r.boundary_edges > 0)
    throw InputError(what + " needs a closed mesh, but this one has " +
                     std::to_string(r.boundary_edges) +
                     " boundary edges (holes); close the holes first");
  if (r.non_manifold_edges > 0)
    throw InputError(what + " needs an edge-manifold mesh, but this one has " +
                     std::to_string(r.non_manifold_edges) + " edges shared by three or more triangles");
}

ManifoldSplit split_non_manifold(const Mesh& mesh, const std::string& what) {
  validate_mesh(mesh, what);
  const MeshReport report = analyze(mesh);
  ManifoldSplit out;
  if (report.non_manifold_edges == 0 || report.boundary_edges > 0) {
    require_closed(mesh, what);  // throws for open meshes; otherwise nothing to split
    return out;
  }
  const std::size_t faces = mesh.triangles.size();
  // Per undirected edge: its (face, corner) uses; corner i is the edge t[i] -> t[i + 1].
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> uses;
  for (std::uint32_t f = 0; f < faces; ++f)
    for (std::uint32_t i = 0; i < 3; ++i) {
      const std::uint32_t a = mesh.triangles[f][i], b = mesh.triangles[f][(i + 1) % 3];
      uses[{std::min(a, b), std::max(a, b)}].push_back(3 * f + i);
    }
  // partner[3f + i]: the face corner glued to face f across its edge i.
  constexpr std::uint32_t none = UINT32_MAX;
  std::vector<std::uint32_t> partner(3 * faces, none);
  auto from = [&](std::uint32_t c) { return mesh.triangles[c / 3][c % 3]; };
  auto opposite = [&](std::uint32_t c) { return mesh.triangles[c / 3][(c % 3 + 2) % 3]; };
  for (const auto& [edge, list] : uses) {
    if (list.size() == 2) {
      partner[list[0]] = list[1], partner[list[1]] = list[0];
      continue;
    }
    // Sort the triangles by angle about the edge a -> b (a < b); a triangle using it forward
    // has its outward normal cross(e, d) (d: toward its third vertex, orthogonal to e), so its
    // solid side lies toward smaller angles, where the next triangle must use it backward.
    const glm::dvec3 pa(mesh.positions[edge.first]), pb(mesh.positions[edge.second]);
    const glm::dvec3 e = glm::normalize(pb - pa);
    std::vector<std::pair<double, std::uint32_t>> around;
    glm::dvec3 d0(0.0);
    for (std::uint32_t c : list) {
      glm::dvec3 d = glm::dvec3(mesh.positions[opposite(c)]) - pa;
      d -= glm::dot(d, e) * e;
      const double len = glm::length(d);
      d = len > 0.0 ? d / len : glm::dvec3(0.0);
      if (around.empty()) d0 = d;
      around.push_back({std::atan2(glm::dot(glm::cross(d0, d), e), glm::dot(d0, d)), c});
    }
    std::sort(around.begin(), around.end());
    const std::size_t m = around.size();
    for (std::size_t k = 0; k < m; ++k) {
      const std::uint32_t c = around[k].second;
      if (from(c) != edge.first) continue;  // backward uses are paired from their forward partner
      const std::uint32_t g = around[(k + m - 1) % m].second;
      if (from(g) == edge.second && partner[g] == none) partner[c] = g, partner[g] = c;
    }
  }
  // Vertex copies: the corners at a vertex that are glued through an edge at it share a copy.
  UnionFind fans(3 * faces);
  for (std::uint32_t c = 0; c < 3 * faces; ++c) {
    const std::uint32_t p = partner[c];
    if (p == none) continue;
    // Face c/3 has the edge from(c) -> next; face p/3 the same edge backward (or forward if the
    // orientation is inconsistent): glue the corners at equal vertices.
    const std::uint32_t f = c / 3, g = p / 3;
    for (std::uint32_t i = 0; i < 3; ++i)
      for (std::uint32_t j = 0; j < 3; ++j)
        if (mesh.triangles[f][i] == mesh.triangles[g][j] &&
            (mesh.triangles[f][i] == from(c) || mesh.triangles[f][i] == mesh.triangles[f][(c % 3 + 1) % 3]))
          fans.unite(3 * f + i, 3 * g + j);
  }
  const std::size_t n = mesh.positions.size();
  out.mesh.positions = mesh.positions;
  out.original.resize(n);
  for (std::uint32_t v = 0; v < n; ++v) out.original[v] = v;
  std::vector<std::uint8_t> taken(n, 0);
  std::map<std::uint32_t, std::uint32_t> copy_of_fan;  // fan representative -> vertex
  out.mesh.triangles = mesh.triangles;
  for (std::uint32_t c = 0; c < 3 * faces; ++c) {
    const std::uint32_t v = mesh.triangles[c / 3][c % 3];
    const std::uint32_t root = fans.find(c);
    auto [it, inserted] = copy_of_fan.try_emplace(root, v);
    if (inserted && taken[v]) {
      it->second = static_cast<std::uint32_t>(out.mesh.positions.size());
      out.mesh.positions.push_back(mesh.positions[v]);
      out.original.push_back(v);
    }
    taken[v] = 1;
    out.mesh.triangles[c / 3][c % 3] = it->second;
  }
  out.applied = true;
  out.non_manifold_edges = report.non_manifold_edges;
  const MeshReport after = analyze(out.mesh);
  if (after.boundary_edges > 0 || after.non_manifold_edges > 0)
    throw InputError(what + " needs a closed edge-manifold mesh; this one has " +
                     std::to_string(report.non_manifold_edges) +
                     " edges shared by three or more triangles that could not be split into closed "
                     "surfaces (inconsistent orientation or crossing faces)");
  return out;
}

}  // namespace sdfkit::skeleton::detail

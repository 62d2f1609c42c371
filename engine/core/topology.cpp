#include "sdfkit/core/topology.hpp"
#include "sdfkit/core/union_find.hpp"

#include <algorithm>
#include <limits>
#include <numeric>

namespace sdfkit {
namespace {

struct EdgeFace {
  std::uint32_t a, b;  // a < b
  std::uint32_t face;
  bool operator<(const EdgeFace& o) const {
    return a != o.a ? a < o.a : (b != o.b ? b < o.b : face < o.face);
  }
};

// All edges of all triangles with their face, sorted by (a, b, face). Self-edges (a == b) of
// triangles with repeated indices are skipped. A counting sort by a, then each a's few edges
// (about six on a closed mesh) sorted in place: O(F) in practice instead of a comparison sort
// of all 3F entries.
std::vector<EdgeFace> sorted_edges(const Mesh& mesh) {
  const auto each_edge = [&](auto&& visit) {
    for (std::uint32_t f = 0; f < mesh.triangles.size(); ++f) {
      const Triangle& t = mesh.triangles[f];
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t u = t[k], v = t[(k + 1) % 3];
        if (u != v) visit(std::min(u, v), std::max(u, v), f);
      }
    }
  };
  std::size_t n = 0;  // one past the largest index
  for (const Triangle& t : mesh.triangles) n = std::max<std::size_t>(n, std::size_t{std::max({t[0], t[1], t[2]})} + 1);
  if (n > mesh.positions.size() || mesh.triangles.size() > std::numeric_limits<std::uint32_t>::max() / 3) {
    // An index past the vertices (analyze() reports such meshes) or too many corners for the
    // counts: one comparison sort, never an array as long as the largest index.
    std::vector<EdgeFace> edges;
    edges.reserve(mesh.triangles.size() * 3);
    each_edge([&](std::uint32_t a, std::uint32_t b, std::uint32_t f) { edges.push_back({a, b, f}); });
    std::sort(edges.begin(), edges.end());
    return edges;
  }
  std::vector<std::uint32_t> start(n + 1, 0);
  each_edge([&](std::uint32_t a, std::uint32_t, std::uint32_t) { ++start[a + 1]; });
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<EdgeFace> edges(start[n]);
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  each_edge([&](std::uint32_t a, std::uint32_t b, std::uint32_t f) { edges[fill[a]++] = {a, b, f}; });
  for (std::size_t a = 0; a < n; ++a) std::sort(edges.begin() + start[a], edges.begin() + start[a + 1]);
  return edges;
}

Adjacency from_pairs(std::size_t n, std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs) {
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  Adjacency adj;
  adj.offsets.assign(n + 1, 0);
  for (const auto& [i, j] : pairs) ++adj.offsets[i + 1];
  std::partial_sum(adj.offsets.begin(), adj.offsets.end(), adj.offsets.begin());
  adj.indices.resize(pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) adj.indices[k] = pairs[k].second;
  return adj;
}


}  // namespace

Adjacency vertex_adjacency(const Mesh& mesh, std::span<const std::uint8_t> rings_of) {
  // Counting build: every corner contributes its two edge neighbours (with duplicates), then
  // each vertex's short list is sorted and de-duplicated in place and the CSR is compacted.
  // O(F) apart from the per-vertex sorts of about a dozen entries.
  const std::size_t n = mesh.positions.size();
  const auto wanted = [&](std::uint32_t v) { return v < n && (rings_of.empty() || (v < rings_of.size() && rings_of[v])); };
  Adjacency adj;
  adj.offsets.assign(n + 1, 0);
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k)
      if (wanted(t[k])) adj.offsets[t[k] + 1] += 2;
  std::partial_sum(adj.offsets.begin(), adj.offsets.end(), adj.offsets.begin());
  std::vector<std::uint32_t> fill(adj.offsets.begin(), adj.offsets.end() - 1);
  adj.indices.resize(adj.offsets[n]);
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[k];
      if (!wanted(a)) continue;
      adj.indices[fill[a]++] = t[(k + 1) % 3];
      adj.indices[fill[a]++] = t[(k + 2) % 3];
    }
  std::uint32_t out = 0;
  for (std::size_t v = 0; v < n; ++v) {
    const auto begin = adj.indices.begin() + adj.offsets[v], end = adj.indices.begin() + adj.offsets[v + 1];
    std::sort(begin, end);
    const std::uint32_t start = out;
    for (auto it = begin; it != end; ++it)
      if (*it != v && *it < n && (out == start || adj.indices[out - 1] != *it)) adj.indices[out++] = *it;
    adj.offsets[v] = start;
  }
  adj.offsets[n] = out;
  adj.indices.resize(out);
  adj.indices.shrink_to_fit();
  return adj;
}

Adjacency face_adjacency(const Mesh& mesh) {
  const auto edges = sorted_edges(mesh);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].a == edges[i].a && edges[j].b == edges[i].b) ++j;
    for (std::size_t x = i; x < j; ++x)
      for (std::size_t y = i; y < j; ++y)
        if (edges[x].face != edges[y].face) pairs.emplace_back(edges[x].face, edges[y].face);
    i = j;
  }
  return from_pairs(mesh.triangles.size(), pairs);
}

Adjacency vertex_faces(const Mesh& mesh, bool skip_degenerate) {
  const auto skip = [&](const Triangle& t) { return skip_degenerate && (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]); };
  const std::size_t n = mesh.positions.size();
  Adjacency vf;
  vf.offsets.assign(n + 1, 0);
  for (const Triangle& t : mesh.triangles)
    if (!skip(t))
      for (std::uint32_t v : t) ++vf.offsets[v + 1];
  std::partial_sum(vf.offsets.begin(), vf.offsets.end(), vf.offsets.begin());
  vf.indices.resize(vf.offsets[n]);
  std::vector<std::uint32_t> fill(vf.offsets.begin(), vf.offsets.end() - 1);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const Triangle& t = mesh.triangles[f];
    if (skip(t)) continue;
    for (std::uint32_t v : t) vf.indices[fill[v]++] = static_cast<std::uint32_t>(f);
  }
  return vf;
}

MeshReport analyze(const Mesh& mesh) {
  MeshReport r;
  r.vertices = mesh.positions.size();
  r.faces = mesh.triangles.size();
  r.bounds = bounding_box(mesh.positions);
  const auto degenerate = degenerate_faces(mesh);
  r.degenerate_faces = static_cast<std::size_t>(std::count(degenerate.begin(), degenerate.end(), 1));

  const auto edges = sorted_edges(mesh);
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].a == edges[i].a && edges[j].b == edges[i].b) ++j;
    const std::size_t uses = j - i;
    if (uses == 1) ++r.boundary_edges;
    if (uses >= 3) ++r.non_manifold_edges;
    i = j;
  }

  UnionFind uf(mesh.positions.size());
  std::vector<std::uint8_t> used(mesh.positions.size(), 0);
  for (const Triangle& t : mesh.triangles) {
    if (t[0] >= r.vertices || t[1] >= r.vertices || t[2] >= r.vertices) continue;
    uf.unite(t[0], t[1]);
    uf.unite(t[1], t[2]);
    used[t[0]] = used[t[1]] = used[t[2]] = 1;
  }
  for (std::uint32_t v = 0; v < r.vertices; ++v) {
    if (!used[v]) {
      ++r.isolated_vertices;
    } else if (uf.find(v) == v) {
      ++r.components;
    }
  }
  return r;
}

}  // namespace sdfkit

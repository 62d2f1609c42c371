// From a contracted mesh to a skeleton: surgery, embedding refinement, radii, reliability and
// sheets (Shapira et al. 2008, section 5; Au et al. 2008, sections 4-5).

#include "sdfkit/skeleton/skeleton.hpp"

#include "bvh.hpp"
#include "laplacian.hpp"
#include "simplify.hpp"
#include "surgery.hpp"
#include "validate.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"
#include "sdfkit/core/parallel.hpp"
#include "sdfkit/core/topology.hpp"
#include "sdfkit/core/union_find.hpp"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <chrono>
#include <functional>
#include <iterator>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <map>
#include <optional>
#include <numeric>
#include <queue>
#include <set>

namespace sdfkit::skeleton {
namespace {

// Skeleton edges, each as (smaller node index, larger node index).
using EdgeSet = std::set<std::array<std::uint32_t, 2>>;

// Adds the edge (a, b) unless it is a loop or an end is missing (UINT32_MAX).
void add_edge(EdgeSet& edges, std::uint32_t a, std::uint32_t b) {
  if (a != b && a != UINT32_MAX && b != UINT32_MAX) edges.insert({std::min(a, b), std::max(a, b)});
}

// Everything about the input surface that node placement and visibility need.
struct Surface {
  const Mesh& original;
  const Mesh& contracted;
  detail::TriangleBvh bvh;
  std::vector<glm::vec3> normals;  // outward vertex normals
  std::vector<double> weight;      // one-ring areas (refinement weights)
  std::vector<glm::vec3> centre;   // per vertex: a point inside the solid seen from the vertex
  std::vector<float> sdf;          // per vertex SDF of the original (may be empty)
  std::vector<std::vector<glm::vec3>> incident_normals;  // per vertex: its faces' normals
  // Per vertex: its mesh component (bvh.component()). One skeleton per component: a vertex
  // only ever joins a node of its own component, a node is only ever linked to nodes of its
  // own, and a vertex sees a point when no face of its own component is in the way. Two bones
  // that overlap (bones.off) would otherwise see each other's nodes through the solid, and a
  // vertex inside the other bone would see none of its own bone's nodes.
  const std::vector<std::uint32_t>& component;
  float far = 0.0f;                // a length beyond the model (2 x bbox diagonal)

  Surface(const Surface&) = delete;  // `component` refers into bvh
  Surface& operator=(const Surface&) = delete;
  Surface(const Mesh& o, const Mesh& c, const std::vector<float>& s)
      : original(o), contracted(c), bvh(o), normals(vertex_normals(o)),
        weight(detail::one_ring_areas(o)), sdf(s), component(bvh.component()) {
    const std::vector<glm::vec3> face_n = face_normals(o);
    incident_normals.resize(o.positions.size());
    for (std::size_t f = 0; f < o.triangles.size(); ++f)
      for (std::uint32_t v : o.triangles[f])
        if (face_n[f] != glm::vec3(0.0f)) incident_normals[v].push_back(face_n[f]);
    far = 2.0f * bounding_box(o.positions).diagonal();
    // Centre points: with an SDF, u - SDF/2 * n when the vertex sees it inside the solid;
    // otherwise (no SDF, or a vertex on a sharp edge whose cone estimate points past a
    // concavity) an inside point the vertex sees (see seen_inside_point).
    centre.resize(o.positions.size());
    std::vector<std::uint8_t> centre_found(o.positions.size(), 1);
    parallel_for(o.positions.size(), [&](std::size_t begin, std::size_t end) {
      for (auto k = static_cast<std::uint32_t>(begin); k < end; ++k) {
        const glm::vec3 u = o.positions[k];
        if (!sdf.empty()) {
          const glm::vec3 p = u - 0.5f * sdf[k] * normals[k];
          if (!bvh.segment_blocked(u, p, k) && bvh.inside(p)) {
            centre[k] = p;
            continue;
          }
        }
        const std::optional<glm::vec3> seen = seen_inside_point(k, {u - normals[k], c.positions[k]});
        centre_found[k] = seen.has_value();
        centre[k] = seen.value_or(c.positions[k]);
      }
    });
    // A vertex with no inside point it sees (a zero-thickness fin, a thin wing) takes its
    // contracted position when that is inside, else the centre point of the nearest vertex
    // (fewest mesh edges, then distance) that found one: never an unchecked point, so nodes
    // placed from centre points stay inside. Only a component where no vertex found one keeps
    // the contracted positions.
    std::vector<std::vector<std::uint32_t>> ring(o.positions.size());
    bool any_missing = false;
    for (std::size_t k = 0; k < o.positions.size(); ++k) any_missing = any_missing || !centre_found[k];
    if (any_missing) {
      for (const Triangle& t : o.triangles)
        for (int i = 0; i < 3; ++i) ring[t[i]].push_back(t[(i + 1) % 3]), ring[t[(i + 1) % 3]].push_back(t[i]);
      for (auto& r : ring) {
        std::sort(r.begin(), r.end());
        r.erase(std::unique(r.begin(), r.end()), r.end());
      }
    }
    for (auto k = static_cast<std::uint32_t>(0); k < o.positions.size(); ++k) {
      if (centre_found[k]) continue;
      if (bvh.inside(c.positions[k])) {
        centre[k] = c.positions[k];
        continue;
      }
      std::vector<std::uint32_t> frontier{k};
      std::set<std::uint32_t> visited{k};
      while (!frontier.empty()) {
        std::uint32_t best = UINT32_MAX;
        float best_d = std::numeric_limits<float>::infinity();
        for (std::uint32_t v : frontier)
          if (centre_found[v]) {
            const float d = glm::length(o.positions[v] - o.positions[k]);
            if (d < best_d || (d == best_d && v < best)) best_d = d, best = v;
          }
        if (best != UINT32_MAX) {
          centre[k] = centre[best];
          break;
        }
        std::vector<std::uint32_t> next;
        for (std::uint32_t v : frontier)
          for (std::uint32_t w : ring[v])
            if (visited.insert(w).second) next.push_back(w);
        std::sort(next.begin(), next.end());
        frontier = std::move(next);
      }
    }
  }

  // A node's mesh component (its vertices share one); UINT32_MAX for a node without vertices.
  std::uint32_t component_of(const Node& node) const {
    return node.vertices.empty() ? UINT32_MAX : component[node.vertices.front()];
  }

  bool sees(std::uint32_t k, const glm::vec3& p) const {
    return !bvh.segment_blocked(original.positions[k], p, k, component[k]);
  }

  // A point inside the solid that vertex k sees: half way from the vertex to the first surface
  // met toward each target in turn, then along each incident face's inward normal, the first
  // that is inside. A vertex on a sharp edge can graze the surface toward one target, and
  // where normals fold (CGAL's cow) the vertex normal can point out of the solid. None where
  // no such point is found (a vertex on a zero-thickness fin: one on CGAL's cow).
  std::optional<glm::vec3> seen_inside_point(std::uint32_t k,
                                             std::initializer_list<glm::vec3> targets) const {
    const glm::vec3 u = original.positions[k];
    auto try_direction = [&](glm::vec3 d, glm::vec3& out) {
      const float len = glm::length(d);
      if (!(len > 0.0f)) return false;
      d /= len;
      const auto hit = bvh.closest(u, d, 0.0f, far, k);
      if (!hit.found) return false;
      const glm::vec3 p = u + 0.5f * hit.t * d;
      if (!bvh.inside(p) || !sees(k, p)) return false;
      out = p;
      return true;
    };
    glm::vec3 p;
    for (const glm::vec3& t : targets)
      if (try_direction(t - u, p)) return p;
    for (const glm::vec3& fn : incident_normals[k])
      if (try_direction(-fn, p)) return p;
    return std::nullopt;
  }

  // A point inside the solid that vertex k sees, for a sheet node: the contracted position if
  // that works, else the centre point, else seen_inside_point toward the contracted position
  // and along -n; none when there is no such point.
  std::optional<glm::vec3> sheet_point(std::uint32_t k) const {
    const glm::vec3 u = original.positions[k], v = contracted.positions[k];
    if (bvh.inside(v) && sees(k, v)) return v;
    if (bvh.inside(centre[k]) && sees(k, centre[k])) return centre[k];
    return seen_inside_point(k, {v, u - normals[k]});
  }

  // A node's position (embedding refinement): the mean of its vertices' centre points, i.e.
  // the centre of the part of the solid that the node's surface region encloses. Au et al. move
  // the node by the mean offset (original - contracted) of its vertices instead; that assumes
  // the vertices surround the node, which half-edge collapses do not ensure (measured on a
  // torus: nodes up to 0.36 (0.7 tube radii) off the ring, 11% of the vertices could not see
  // their node). The first candidate inside the solid wins: the mean of the centre points,
  // Au's offset, the contracted position; else the centre point of the vertex closest to the
  // contracted position (inside by construction).
  glm::vec3 place(const glm::vec3& contracted_position, const std::vector<std::uint32_t>& members,
                  bool refine) const {
    std::vector<glm::vec3> candidates;
    if (refine) {
      glm::dvec3 mean(0.0);
      for (std::uint32_t k : members) mean += glm::dvec3(centre[k]);
      candidates.push_back(glm::vec3(mean / static_cast<double>(members.size())));
      glm::dvec3 offset(0.0);
      double total = 0.0;
      for (std::uint32_t k : members) {
        offset += weight[k] * glm::dvec3(original.positions[k] - contracted.positions[k]);
        total += weight[k];
      }
      if (total > 0.0) candidates.push_back(contracted_position + glm::vec3(offset / total));
    }
    candidates.push_back(contracted_position);
    // Last resorts: the centre points of the vertices, closest to the contracted position first.
    std::vector<std::pair<float, std::uint32_t>> by_distance;
    for (std::uint32_t k : members)
      by_distance.push_back({glm::length(original.positions[k] - contracted_position), k});
    std::sort(by_distance.begin(), by_distance.end());
    for (std::size_t i = 0; i < std::min<std::size_t>(by_distance.size(), 16); ++i)
      candidates.push_back(centre[by_distance[i].second]);
    for (const glm::vec3& c : candidates)
      if (bvh.inside(c)) return c;
    return contracted_position;  // nothing inside: degenerate geometry (zero-thickness parts)
  }

  // A node's radius: the mean SDF/2 of its vertices, or without an SDF the mean distance from
  // the node to them.
  float radius(const glm::vec3& p, const std::vector<std::uint32_t>& members) const {
    double s = 0.0;
    for (std::uint32_t k : members)
      s += sdf.empty() ? glm::length(original.positions[k] - p) : 0.5 * sdf[k];
    return static_cast<float>(s / static_cast<double>(members.size()));
  }

  // Where a region of vertices (`part`, not empty) gets a curve node: the mean of its centre
  // points, or where that is outside the solid (a centre point can be outside where no inside
  // point was found for its vertex: thin wings and fins) the nearest of its 16 nearest centre
  // points that is inside; with the vertices of `part` that see it. nullopt when none of the 16
  // is inside or under half of the vertices see the point.
  struct RegionNode {
    glm::vec3 point;
    std::vector<std::uint32_t> seeing;
  };
  std::optional<RegionNode> region_node(const std::vector<std::uint32_t>& part) const {
    glm::dvec3 mean(0.0);
    for (std::uint32_t k : part) mean += glm::dvec3(centre[k]);
    glm::vec3 p(mean / static_cast<double>(part.size()));
    if (!bvh.inside(p)) {
      std::vector<std::pair<float, std::uint32_t>> by_distance;
      for (std::uint32_t k : part) by_distance.push_back({glm::length(centre[k] - p), k});
      const std::size_t tried = std::min<std::size_t>(by_distance.size(), 16);
      std::partial_sort(by_distance.begin(), by_distance.begin() + static_cast<std::ptrdiff_t>(tried),
                        by_distance.end());
      bool found = false;
      for (std::size_t i = 0; i < tried && !found; ++i)
        if (bvh.inside(centre[by_distance[i].second])) p = centre[by_distance[i].second], found = true;
      if (!found) return std::nullopt;
    }
    RegionNode node{p, {}};
    for (std::uint32_t k : part)
      if (sees(k, p)) node.seeing.push_back(k);
    if (node.seeing.empty() || 2 * node.seeing.size() < part.size()) return std::nullopt;
    return node;
  }

  // Of the nodes `candidates` (index, position), the nearest to p of the 64 nearest whose
  // segment to p stays inside the solid (ties to the lower index); UINT32_MAX when none does.
  std::uint32_t nearest_seen_node(const glm::vec3& p, const std::vector<std::pair<std::uint32_t, glm::vec3>>& candidates) const {
    std::vector<std::pair<float, std::uint32_t>> by_distance;
    for (std::size_t i = 0; i < candidates.size(); ++i)
      by_distance.push_back({glm::length(candidates[i].second - p), static_cast<std::uint32_t>(i)});
    const std::size_t tried = std::min<std::size_t>(by_distance.size(), 64);
    std::partial_sort(by_distance.begin(), by_distance.begin() + static_cast<std::ptrdiff_t>(tried), by_distance.end());
    for (std::size_t i = 0; i < tried; ++i)
      if (!bvh.segment_blocked(p, candidates[by_distance[i].second].second)) return candidates[by_distance[i].second].first;
    return UINT32_MAX;
  }
};

// Sheet nodes: the sheet vertices' sheet points (`point`, from Surface::sheet_point) clustered on a grid of
// cell `spacing` (model units; 0 = one node per vertex). A cluster's node sits at the mean of
// its sheet points (or, when that is outside the solid, at the member's point closest to it);
// a member that cannot see it keeps a node of its own at its sheet point, so every sheet vertex
// sees its node.
void add_sheet_nodes(const Surface& surface, const std::vector<std::uint8_t>& in_sheet,
                     const std::vector<glm::vec3>& point, double spacing, std::vector<Node>& nodes,
                     std::vector<std::uint32_t>& node_of_vertex) {
  // Cells are per mesh component: a sheet node holds vertices of one component.
  std::map<std::array<std::int64_t, 4>, std::vector<std::uint32_t>> cells;
  for (std::uint32_t k = 0; k < in_sheet.size(); ++k) {
    if (!in_sheet[k]) continue;
    std::array<std::int64_t, 4> key{surface.component[k], static_cast<std::int64_t>(k), 0, 0};
    if (spacing > 0.0)
      for (int a = 0; a < 3; ++a) key[a + 1] = static_cast<std::int64_t>(std::floor(point[k][a] / spacing));
    cells[key].push_back(k);
  }
  auto add = [&](const glm::vec3& p, std::vector<std::uint32_t> members) {
    Node node;
    node.sheet = true;
    node.position = p;
    node.vertices = std::move(members);
    node.radius = surface.radius(p, node.vertices);
    for (std::uint32_t k : node.vertices) node_of_vertex[k] = static_cast<std::uint32_t>(nodes.size());
    nodes.push_back(std::move(node));
  };
  // One point per cell: the mean of its sheet points (or the member's point closest to it).
  std::vector<glm::vec3> cell_point;
  std::vector<const std::vector<std::uint32_t>*> cell_members;
  for (const auto& [key, members] : cells) {
    glm::dvec3 mean(0.0);
    for (std::uint32_t k : members) mean += glm::dvec3(point[k]);
    glm::vec3 p(mean / static_cast<double>(members.size()));
    if (!surface.bvh.inside(p)) {
      std::uint32_t best = members.front();
      for (std::uint32_t k : members)
        if (glm::length(point[k] - p) < glm::length(point[best] - p)) best = k;
      p = point[best];
    }
    cell_point.push_back(p);
    cell_members.push_back(&members);
  }
  // A member that cannot see its cell's point joins the nearest of the 8 nearest other cells'
  // points that it sees (a fold of the sheet), and only then gets a node of its own.
  std::vector<std::vector<std::uint32_t>> seeing(cell_point.size());
  std::vector<std::uint32_t> alone;
  for (std::size_t c = 0; c < cell_point.size(); ++c)
    for (std::uint32_t k : *cell_members[c]) {
      if (surface.sees(k, cell_point[c])) {
        seeing[c].push_back(k);
        continue;
      }
      std::vector<std::pair<float, std::size_t>> near;
      for (std::size_t d = 0; d < cell_point.size(); ++d)
        if (d != c && surface.component[cell_members[d]->front()] == surface.component[k])
          near.push_back({glm::length(cell_point[d] - point[k]), d});
      const std::size_t tried = std::min<std::size_t>(near.size(), 8);
      std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(tried), near.end());
      bool placed = false;
      for (std::size_t i = 0; i < tried && !placed; ++i)
        if (surface.sees(k, cell_point[near[i].second])) seeing[near[i].second].push_back(k), placed = true;
      if (!placed) alone.push_back(k);
    }
  for (std::size_t c = 0; c < cell_point.size(); ++c)
    if (!seeing[c].empty()) {
      std::sort(seeing[c].begin(), seeing[c].end());
      add(cell_point[c], std::move(seeing[c]));
    }
  for (std::uint32_t k : alone) add(point[k], {k});
}

// Wall-clock time of the stages of build_skeleton, logged at debug level.
class Stopwatch {
public:
  void lap(const char* stage) {
    const auto now = std::chrono::steady_clock::now();
    log_debug(std::string("skeleton: ") + stage + " " +
              std::to_string(std::chrono::duration<double, std::milli>(now - last_).count()) + " ms");
    last_ = now;
  }

private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// Nodes nearest to a vertex that are tried when it cannot see its own node.
constexpr std::size_t kNearestNodes = 8;
// Regions of vertices that see no curve node are split into pieces on a grid of this cell
// (fraction of the bbox diagonal) ...
constexpr double kRegionCell = 0.05;
// ... and a piece is flat (part of a sheet) when the second principal spread of its centre
// points exceeds this fraction of the first, and around it the region's centre points spread in
// a second direction further than the solid is thick there (see split_region).
constexpr double kFlatRatio = 0.25;
// A flat region becomes a sheet only when it holds at least this share of the surface's
// vertices; a smaller one (a palm, a fist, a flat ear's tip) gets curve nodes.
constexpr double kSheetRegionShare = 0.05;

// Where the point of the segment ab nearest q lies, as t in [0, 1] (a + t (b - a)).
float segment_parameter(const glm::vec3& q, const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  return len2 > 0.0f ? std::clamp(glm::dot(q - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
}

// Distance from q to the segment ab.
float distance_to_segment(const glm::vec3& q, const glm::vec3& a, const glm::vec3& b) {
  return glm::length(q - (a + segment_parameter(q, a, b) * (b - a)));
}

// The skeleton stands for the union of its curve nodes' balls swept along its curve edges, the
// radius interpolated linearly along each edge. How far q lies outside the part swept along the
// edge (a, b): its distance to the nearest point of the segment minus the radius there (< 0:
// inside).
float outside_swept_ball(const glm::vec3& q, const glm::vec3& a, float ra, const glm::vec3& b, float rb) {
  const float t = segment_parameter(q, a, b);
  return glm::length(q - (a + t * (b - a))) - (ra + t * (rb - ra));
}
float outside_swept_ball(const glm::vec3& q, const Node& a, const Node& b) {
  return outside_swept_ball(q, a.position, a.radius, b.position, b.radius);
}

// Drops the nodes marked in `dead` (no sheet triangle may use them) and renumbers the rest in
// order, in the sheet triangles and `node_of_vertex`; returns the new index of each old node
// (UINT32_MAX for a dropped one) for the caller's edge sets (renumbered).
std::vector<std::uint32_t> remove_nodes(Skeleton& sk, const std::vector<std::uint8_t>& dead,
                                        std::vector<std::uint32_t>& node_of_vertex) {
  std::vector<std::uint32_t> index(sk.nodes.size(), UINT32_MAX);
  std::vector<Node> kept;
  for (std::uint32_t k = 0; k < sk.nodes.size(); ++k)
    if (!dead[k]) index[k] = static_cast<std::uint32_t>(kept.size()), kept.push_back(std::move(sk.nodes[k]));
  sk.nodes = std::move(kept);
  for (Triangle& t : sk.sheet_triangles)
    for (std::uint32_t& v : t) v = index[v];
  for (std::uint32_t& v : node_of_vertex)
    if (v != UINT32_MAX) v = index[v];
  return index;
}

// `edges` with their ends renumbered by `index` (remove_nodes); none may end at a dropped node.
EdgeSet renumbered(const EdgeSet& edges, const std::vector<std::uint32_t>& index) {
  EdgeSet out;
  for (const auto& e : edges) out.insert({std::min(index[e[0]], index[e[1]]), std::max(index[e[0]], index[e[1]])});
  return out;
}

// Edges whose segment leaves the solid (embedding refinement moved their ends apart around a
// concavity, or a sheet link crosses a fold) are replaced by a detour through the node c that
// minimizes |ac| + |cb| with both segments inside (of the 256 best); without one, where
// dropping the edge splits the skeleton, the two parts are joined again by the shortest
// segment between them that stays inside (of the 256 shortest pairs). An edge that neither
// finds is kept (a connected skeleton with its cycles comes first) and returned, so that the
// cycle pruning (prune_cycles) drops it before any edge inside.
EdgeSet route_edges_inside(Skeleton& sk, EdgeSet& edges, std::vector<std::uint32_t>& node_of_vertex, const Surface& surface) {
  const Mesh& original = surface.original;
  const std::size_t n = original.positions.size();
  EdgeSet through_air;
  std::vector<std::array<std::uint32_t, 2>> blocked;
  for (const auto& e : edges)
    if (surface.bvh.segment_leaves(sk.nodes[e[0]].position, sk.nodes[e[1]].position)) blocked.push_back(e);
  auto inside_segment = [&](std::uint32_t a, std::uint32_t b) {
    return !surface.bvh.segment_blocked(sk.nodes[a].position, sk.nodes[b].position);
  };
  if (!blocked.empty()) {
    // Genus of the mesh component of each vertex (Euler characteristic per component).
    std::vector<int> vertex_genus(n, 0);
    {
      UnionFind comp(n);
      const std::map<std::uint32_t, int> genus = detail::component_genus(original, comp);
      for (std::uint32_t k = 0; k < n; ++k) {
        const auto it = genus.find(comp.find(k));
        vertex_genus[k] = it == genus.end() ? 0 : it->second;
      }
    }
    auto in_handle_body = [&](std::uint32_t node) {
      return !sk.nodes[node].vertices.empty() && vertex_genus[sk.nodes[node].vertices.front()] > 0;
    };
    for (const auto& e : blocked) edges.erase(e);
    std::vector<std::array<std::uint32_t, 2>> unresolved;
    for (const auto& e : blocked) {
      const glm::vec3 pa = sk.nodes[e[0]].position, pb = sk.nodes[e[1]].position;
      std::vector<std::pair<float, std::uint32_t>> via;
      const std::uint32_t comp = surface.component_of(sk.nodes[e[0]]);
      for (std::uint32_t c = 0; c < sk.nodes.size(); ++c)
        if (c != e[0] && c != e[1] && surface.component_of(sk.nodes[c]) == comp)
          via.push_back({glm::length(sk.nodes[c].position - pa) + glm::length(sk.nodes[c].position - pb), c});
      const std::size_t tried = std::min<std::size_t>(via.size(), 256);
      std::partial_sort(via.begin(), via.begin() + static_cast<std::ptrdiff_t>(tried), via.end());
      bool detoured = false;
      // In a component of genus > 0, a detour along two edges the skeleton already has would
      // drop the edge's cycle (a coarse handle's ring of three nodes: P, 3torus); those wait
      // for a detour through a new node below.
      const bool keep_cycle = in_handle_body(e[0]);
      for (std::size_t i = 0; i < tried && !detoured; ++i)
        if (!(keep_cycle && edges.count({std::min(e[0], via[i].second), std::max(e[0], via[i].second)}) &&
              edges.count({std::min(e[1], via[i].second), std::max(e[1], via[i].second)})) &&
            inside_segment(e[0], via[i].second) && inside_segment(via[i].second, e[1])) {
          add_edge(edges, e[0], via[i].second);
          add_edge(edges, via[i].second, e[1]);
          detoured = true;
        }
      if (!detoured) unresolved.push_back(e);
    }
    log_debug("skeleton: " + std::to_string(blocked.size()) + " edges leave the solid, " +
              std::to_string(blocked.size() - unresolved.size()) + " detoured");
    // Then a detour through a new node at the centre point of one of the two nodes' vertices
    // (the vertex moves to the new node; its old node keeps at least one vertex).
    std::vector<std::array<std::uint32_t, 2>> still;
    for (const auto& e : unresolved) {
      const glm::vec3 pa = sk.nodes[e[0]].position, pb = sk.nodes[e[1]].position;
      std::vector<std::pair<float, std::pair<std::uint32_t, std::uint32_t>>> via;  // (vertex, node)
      for (std::uint32_t end : e)
        if (!sk.nodes[end].sheet && sk.nodes[end].vertices.size() > 1)
          for (std::uint32_t k : sk.nodes[end].vertices)
            via.push_back({glm::length(surface.centre[k] - pa) + glm::length(surface.centre[k] - pb), {k, end}});
      const std::size_t tried = std::min<std::size_t>(via.size(), 256);
      std::partial_sort(via.begin(), via.begin() + static_cast<std::ptrdiff_t>(tried), via.end());
      bool detoured = false;
      for (std::size_t i = 0; i < tried && !detoured; ++i) {
        const auto [k, end] = via[i].second;
        const glm::vec3 c = surface.centre[k];
        if (sk.nodes[end].vertices.size() < 2 || !surface.bvh.inside(c) ||
            surface.bvh.segment_blocked(pa, c) || surface.bvh.segment_blocked(c, pb))
          continue;
        std::erase(sk.nodes[end].vertices, k);
        Node node;
        node.position = c;
        node.vertices = {k};
        node.radius = surface.radius(c, node.vertices);
        const auto id = static_cast<std::uint32_t>(sk.nodes.size());
        sk.nodes.push_back(std::move(node));
        node_of_vertex[k] = id;
        add_edge(edges, e[0], id);
        add_edge(edges, id, e[1]);
        detoured = true;
      }
      if (!detoured) still.push_back(e);
    }
    // Then the shortest path from one end to the other through nodes whose surface regions
    // touch (a mesh edge joins their vertices), every step inside the solid: the skeleton
    // follows the surface around the concavity the edge cut across.
    std::vector<std::array<std::uint32_t, 2>> unrouted;
    if (!still.empty()) {
      std::vector<std::vector<std::uint32_t>> touching(sk.nodes.size());
      for (const Triangle& t : original.triangles)
        for (int i = 0; i < 3; ++i) {
          const std::uint32_t a = node_of_vertex[t[i]], b = node_of_vertex[t[(i + 1) % 3]];
          if (a != b && a != UINT32_MAX && b != UINT32_MAX) touching[a].push_back(b);
        }
      for (auto& list : touching) {
        std::sort(list.begin(), list.end());
        list.erase(std::unique(list.begin(), list.end()), list.end());
      }
      std::map<std::array<std::uint32_t, 2>, bool> inside_cache;
      auto step_inside = [&](std::uint32_t a, std::uint32_t b) {
        const std::array<std::uint32_t, 2> key{std::min(a, b), std::max(a, b)};
        const auto it = inside_cache.find(key);
        if (it != inside_cache.end()) return it->second;
        return inside_cache[key] = inside_segment(a, b);
      };
      for (const auto& e : still) {
        std::vector<float> dist(sk.nodes.size(), std::numeric_limits<float>::infinity());
        std::vector<std::uint32_t> from(sk.nodes.size(), UINT32_MAX);
        using Item = std::pair<float, std::uint32_t>;
        std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
        dist[e[0]] = 0.0f;
        queue.push({0.0f, e[0]});
        while (!queue.empty()) {
          const auto [d, x] = queue.top();
          queue.pop();
          if (d > dist[x]) continue;
          if (x == e[1]) break;
          for (std::uint32_t y : touching[x]) {
            if ((x == e[0] && y == e[1]) || (x == e[1] && y == e[0])) continue;
            const float nd = d + glm::length(sk.nodes[x].position - sk.nodes[y].position);
            if (nd < dist[y] && step_inside(x, y)) {
              dist[y] = nd, from[y] = x;
              queue.push({nd, y});
            }
          }
        }
        if (from[e[1]] == UINT32_MAX) {
          unrouted.push_back(e);
          continue;
        }
        for (std::uint32_t y = e[1]; y != e[0]; y = from[y]) add_edge(edges, from[y], y);
      }
      log_debug("skeleton: " + std::to_string(still.size() - unrouted.size()) + " of " +
                std::to_string(still.size()) + " edges re-routed along touching regions");
    }
    // Last, a chain of new nodes along the centre points of a path of surface vertices from
    // one end's vertices to the other's (Dijkstra over mesh edges, near the edge: centre points
    // within |ab| of its midpoint; every step between centre points inside), thinned to the
    // farthest visible centre point at each step; each new node takes its vertex from a node
    // that keeps at least one. Where no such path stays near the edge, the same search over
    // all the solid's inside centre points, from either end (a search seeded at one end can
    // be walled in where the other's is not: camel's one bridge through the air, mpi's sheet
    // links; s11fix).
    std::vector<std::array<std::uint32_t, 2>> left;
    if (!unrouted.empty()) {
      std::vector<std::vector<std::uint32_t>> vertex_nbrs(n);
      for (const Triangle& t : original.triangles)
        for (int i = 0; i < 3; ++i) vertex_nbrs[t[i]].push_back(t[(i + 1) % 3]), vertex_nbrs[t[(i + 1) % 3]].push_back(t[i]);
      // A step between two centre points that does not cross the surface is inside only when
      // the points are: a vertex whose centre point fell back to its contracted position (a
      // thin wing where no inside point was found) could route the chain through the air.
      std::vector<std::int8_t> centre_in(n, -1);
      auto inside_centre = [&](std::uint32_t k) {
        if (centre_in[k] < 0) centre_in[k] = surface.bvh.inside(surface.centre[k]) ? 1 : 0;
        return centre_in[k] == 1;
      };
      // `near_only`: the centre points within |ab| of the edge's midpoint (a local detour);
      // without it, any inside centre point (the whole solid's, for an edge that the local
      // search could not route round a deep concavity: camel, bones).
      auto route_chain = [&](const std::array<std::uint32_t, 2>& e, bool near_only) {
        const glm::vec3 pa = sk.nodes[e[0]].position, pb = sk.nodes[e[1]].position;
        const glm::vec3 mid = 0.5f * (pa + pb);
        const float reach = glm::length(pb - pa);
        auto near = [&](std::uint32_t k) {
          return (!near_only || glm::length(surface.centre[k] - mid) <= reach) && inside_centre(k);
        };
        std::map<std::uint32_t, float> dist;
        std::map<std::uint32_t, std::uint32_t> from;
        using Item = std::pair<float, std::uint32_t>;
        std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
        for (std::uint32_t k : sk.nodes[e[0]].vertices)
          if (near(k) && !surface.bvh.segment_blocked(pa, surface.centre[k])) {
            const float d = glm::length(surface.centre[k] - pa);
            dist[k] = d, from[k] = UINT32_MAX;
            queue.push({d, k});
          }
        std::uint32_t reached = UINT32_MAX;
        std::size_t settled = 0;
        while (!queue.empty() && settled < (near_only ? std::size_t{20000} : n)) {
          const auto [d, k] = queue.top();
          queue.pop();
          if (d > dist[k]) continue;
          ++settled;
          if (node_of_vertex[k] == e[1] && !surface.bvh.segment_blocked(surface.centre[k], pb)) {
            reached = k;
            break;
          }
          for (std::uint32_t l : vertex_nbrs[k]) {
            if (!near(l)) continue;
            const float nd = d + glm::length(surface.centre[l] - surface.centre[k]);
            const auto it = dist.find(l);
            if ((it == dist.end() || nd < it->second) &&
                !surface.bvh.segment_blocked(surface.centre[k], surface.centre[l])) {
              dist[l] = nd, from[l] = k;
              queue.push({nd, l});
            }
          }
        }
        if (reached == UINT32_MAX) return false;
        std::vector<std::uint32_t> path;
        for (std::uint32_t k = reached; k != UINT32_MAX; k = from[k]) path.push_back(k);
        std::reverse(path.begin(), path.end());
        // Waypoints: from the current point, the farthest path vertex whose centre it sees.
        std::vector<std::uint32_t> waypoints;
        glm::vec3 current = pa;
        std::size_t i = 0;
        while (surface.bvh.segment_blocked(current, pb) && i < path.size()) {
          std::size_t j = path.size() - 1;
          while (j > i && surface.bvh.segment_blocked(current, surface.centre[path[j]])) --j;
          waypoints.push_back(path[j]);
          current = surface.centre[path[j]];
          i = j + 1;
        }
        bool ok = !surface.bvh.segment_blocked(current, pb);
        // Each waypoint's node stands for one vertex that sees it: the path vertex whose centre
        // point it is, or, where that vertex's node has no other (a coarse mesh's nodes hold a
        // few vertices each: mpi_triang), the nearest vertex of the same piece that sees the
        // waypoint and whose node keeps one.
        std::map<std::uint32_t, std::size_t> taken;  // node -> vertices taken from it
        std::vector<std::uint32_t> owner;            // per waypoint: the vertex its node takes
        auto spare = [&](std::uint32_t k) {
          const std::uint32_t node = node_of_vertex[k];
          return node != UINT32_MAX && sk.nodes[node].vertices.size() >= 2 + taken[node] &&
                 std::find(owner.begin(), owner.end(), k) == owner.end();
        };
        for (std::uint32_t k : waypoints) {
          std::uint32_t chosen = spare(k) ? k : UINT32_MAX;
          if (chosen == UINT32_MAX) {
            const glm::vec3 w = surface.centre[k];
            float best = std::numeric_limits<float>::infinity();
            for (std::uint32_t v = 0; v < n; ++v) {
              const float d = glm::length(original.positions[v] - w);
              if (d < best && surface.component[v] == surface.component[k] && spare(v) && surface.sees(v, w))
                best = d, chosen = v;
            }
          }
          if (chosen == UINT32_MAX) return false;
          ++taken[node_of_vertex[chosen]];
          owner.push_back(chosen);
        }
        if (!ok) return false;
        std::uint32_t previous = e[0];
        for (std::size_t w = 0; w < waypoints.size(); ++w) {
          const std::uint32_t k = owner[w];
          std::erase(sk.nodes[node_of_vertex[k]].vertices, k);
          Node node;
          node.position = surface.centre[waypoints[w]];
          node.vertices = {k};
          node.radius = surface.radius(node.position, node.vertices);
          const auto id = static_cast<std::uint32_t>(sk.nodes.size());
          sk.nodes.push_back(std::move(node));
          node_of_vertex[k] = id;
          add_edge(edges, previous, id);
          previous = id;
        }
        add_edge(edges, previous, e[1]);
        return true;
      };
      for (const auto& e : unrouted)
        if (!route_chain(e, true) && !route_chain(e, false) && !route_chain({e[1], e[0]}, false)) left.push_back(e);
      log_debug("skeleton: " + std::to_string(unrouted.size() - left.size()) + " of " +
                std::to_string(unrouted.size()) + " edges re-routed along centre points");
    }
    UnionFind parts(sk.nodes.size());
    for (const auto& e : edges) parts.unite(e[0], e[1]);
    for (const Triangle& t : sk.sheet_triangles) parts.unite(t[0], t[1]), parts.unite(t[1], t[2]);
    for (const auto& e : left) {
      const std::uint32_t ra = parts.find(e[0]), rb = parts.find(e[1]);
      if (ra == rb) {
        add_edge(edges, e[0], e[1]);
        through_air.insert(e);
        continue;
      }
      std::vector<std::uint32_t> in_a, in_b;
      for (std::uint32_t v = 0; v < sk.nodes.size(); ++v) {
        const std::uint32_t r = parts.find(v);
        if (r == ra) in_a.push_back(v);
        else if (r == rb) in_b.push_back(v);
      }
      std::vector<std::pair<float, std::array<std::uint32_t, 2>>> pairs;
      for (std::uint32_t a : in_a)
        for (std::uint32_t b : in_b)
          if (surface.component_of(sk.nodes[a]) == surface.component_of(sk.nodes[b]))
            pairs.push_back({glm::length(sk.nodes[a].position - sk.nodes[b].position), {a, b}});
      const std::size_t tried = std::min<std::size_t>(pairs.size(), 256);
      std::partial_sort(pairs.begin(), pairs.begin() + static_cast<std::ptrdiff_t>(tried), pairs.end());
      std::array<std::uint32_t, 2> join = e;
      through_air.insert(e);
      for (std::size_t i = 0; i < tried; ++i) {
        const auto [a, b] = pairs[i].second;
        if (!surface.bvh.segment_blocked(sk.nodes[a].position, sk.nodes[b].position)) {
          join = pairs[i].second;
          through_air.erase(e);
          break;
        }
      }
      add_edge(edges, join[0], join[1]);
      parts.unite(join[0], join[1]);
    }
  }
  return through_air;
}

// A solid of genus g has a skeleton with g independent cycles. Nodes added for unseen regions,
// re-routed edges and sheet links can close more: with each sheet piece taken as one unit,
// the curve edges that close a cycle (shortest edges first into a spanning forest) are
// collected per mesh component, and all but the g longest of them are dropped.
void prune_cycles(Skeleton& sk, EdgeSet& edges, const EdgeSet& through_air, const Mesh& original) {
  const std::size_t n = original.positions.size();
  UnionFind mesh_parts(n);
  for (const Triangle& t : original.triangles) mesh_parts.unite(t[0], t[1]), mesh_parts.unite(t[1], t[2]);
  std::map<std::uint32_t, long long> chi;
  std::vector<std::uint8_t> used(n, 0);
  for (const Triangle& t : original.triangles) {
    const std::uint32_t r = mesh_parts.find(t[0]);
    chi[r] += 1;
    for (std::uint32_t v : t)
      if (!used[v]) used[v] = 1, chi[r] += 1;
  }
  std::set<std::array<std::uint32_t, 2>> mesh_edges;
  for (const Triangle& t : original.triangles)
    for (int i = 0; i < 3; ++i) mesh_edges.insert({std::min(t[i], t[(i + 1) % 3]), std::max(t[i], t[(i + 1) % 3])});
  for (const auto& e : mesh_edges) chi[mesh_parts.find(e[0])] -= 1;
  // A sheet's own cycles (a band of sheet triangles around a hole) count against the genus:
  // every closing curve edge below adds one independent cycle to those of the sheets (its
  // ends are already joined), so a component keeps g minus its sheets' first Betti number.
  // Where the sheets alone have more cycles than the genus, the holes are closed, shortest
  // first: a fundamental cycle of the sheet edges that no set of sheet triangles bounds gets a
  // fan of triangles from its first node (each fan removes exactly that cycle).
  std::map<std::uint32_t, std::size_t> sheet_cycles;
  {
    std::map<std::uint32_t, Skeleton> sheets_of;
    for (const Triangle& t : sk.sheet_triangles)
      for (std::uint32_t node : t)
        if (!sk.nodes[node].vertices.empty()) {
          sheets_of[mesh_parts.find(sk.nodes[node].vertices.front())].sheet_triangles.push_back(t);
          break;
        }
    for (auto& [root, part] : sheets_of) {
      part.nodes.resize(sk.nodes.size());
      const auto g = static_cast<std::size_t>(std::max(0LL, (2 - chi[root]) / 2));
      auto betti = static_cast<std::size_t>(cycle_count(part));
      if (betti > g) {
        // Fundamental cycles of a spanning forest of the sheet edges (shortest edges first)
        // span every cycle of the sheets; one that is not a sum of triangle boundaries (its
        // edge vector does not reduce to zero against the boundary columns, Z/2) is a hole.
        std::map<std::array<std::uint32_t, 2>, std::uint32_t> edge_id;
        for (const Triangle& t : part.sheet_triangles)
          for (int i = 0; i < 3; ++i)
            edge_id.emplace(std::array<std::uint32_t, 2>{std::min(t[i], t[(i + 1) % 3]), std::max(t[i], t[(i + 1) % 3])}, 0u);
        std::uint32_t next_id = 0;
        for (auto& [e, id] : edge_id) id = next_id++;
        auto id_of = [&](std::uint32_t a, std::uint32_t b) { return edge_id.at({std::min(a, b), std::max(a, b)}); };
        std::vector<std::vector<std::uint32_t>> columns;  // descending edge ids
        std::map<std::uint32_t, std::size_t> pivot_of;
        auto reduce = [&](std::vector<std::uint32_t> c) {
          while (!c.empty()) {
            const auto holder = pivot_of.find(c.front());
            if (holder == pivot_of.end()) break;
            std::vector<std::uint32_t> sum;
            std::set_symmetric_difference(c.begin(), c.end(), columns[holder->second].begin(),
                                          columns[holder->second].end(), std::back_inserter(sum), std::greater<>());
            c = std::move(sum);
          }
          return c;
        };
        auto add_column = [&](std::vector<std::uint32_t> c) {
          c = reduce(std::move(c));
          if (c.empty()) return;
          pivot_of.emplace(c.front(), columns.size());
          columns.push_back(std::move(c));
        };
        for (const Triangle& t : part.sheet_triangles) {
          std::vector<std::uint32_t> c{id_of(t[0], t[1]), id_of(t[1], t[2]), id_of(t[2], t[0])};
          std::sort(c.begin(), c.end(), std::greater<>());
          c.erase(std::unique(c.begin(), c.end()), c.end());
          add_column(std::move(c));
        }
        std::vector<std::pair<float, std::array<std::uint32_t, 2>>> by_length;
        for (const auto& [e, id] : edge_id)
          by_length.push_back({glm::length(sk.nodes[e[0]].position - sk.nodes[e[1]].position), e});
        std::sort(by_length.begin(), by_length.end());
        UnionFind tree(sk.nodes.size());
        std::map<std::uint32_t, std::vector<std::uint32_t>> adjacency;
        std::vector<std::array<std::uint32_t, 2>> non_tree;
        for (const auto& [length, e] : by_length) {
          if (tree.unite(e[0], e[1]))
            adjacency[e[0]].push_back(e[1]), adjacency[e[1]].push_back(e[0]);
          else
            non_tree.push_back(e);
        }
        std::vector<std::pair<float, std::vector<std::uint32_t>>> loops;
        for (const auto& e : non_tree) {
          std::map<std::uint32_t, std::uint32_t> from{{e[0], e[0]}};
          std::vector<std::uint32_t> queue{e[0]};
          for (std::size_t q = 0; q < queue.size() && !from.count(e[1]); ++q)
            for (std::uint32_t y : adjacency[queue[q]])
              if (from.emplace(y, queue[q]).second) queue.push_back(y);
          std::vector<std::uint32_t> loop{e[1]};
          while (loop.back() != e[0]) loop.push_back(from[loop.back()]);
          float length = glm::length(sk.nodes[e[0]].position - sk.nodes[e[1]].position);
          for (std::size_t i = 0; i + 1 < loop.size(); ++i)
            length += glm::length(sk.nodes[loop[i]].position - sk.nodes[loop[i + 1]].position);
          loops.push_back({length, std::move(loop)});
        }
        std::sort(loops.begin(), loops.end());
        // Shortest hole first: its loop gets a fan of triangles from its first node.
        for (const auto& [length, loop] : loops) {
          if (betti <= g) break;
          std::vector<std::uint32_t> c;
          for (std::size_t i = 0; i < loop.size(); ++i) c.push_back(id_of(loop[i], loop[(i + 1) % loop.size()]));
          std::sort(c.begin(), c.end(), std::greater<>());
          if (reduce(c).empty()) continue;  // bounds already
          add_column(std::move(c));
          for (std::size_t i = 1; i + 1 < loop.size(); ++i) {
            part.sheet_triangles.push_back({loop[0], loop[i], loop[i + 1]});
            sk.sheet_triangles.push_back({loop[0], loop[i], loop[i + 1]});
          }
          --betti;
        }
        betti = static_cast<std::size_t>(cycle_count(part));
      }
      sheet_cycles[root] = betti;
    }
  }
  std::set<std::array<std::uint32_t, 2>> in_triangles;
  UnionFind forest(sk.nodes.size());
  for (const Triangle& t : sk.sheet_triangles) {
    forest.unite(t[0], t[1]), forest.unite(t[1], t[2]);
    for (int i = 0; i < 3; ++i) in_triangles.insert({std::min(t[i], t[(i + 1) % 3]), std::max(t[i], t[(i + 1) % 3])});
  }
  std::vector<std::pair<float, std::array<std::uint32_t, 2>>> by_length;
  for (const auto& e : edges)
    if (!in_triangles.count(e))
      by_length.push_back({glm::length(sk.nodes[e[0]].position - sk.nodes[e[1]].position), e});
  std::sort(by_length.begin(), by_length.end());
  // Edges through the air go into the forest last (so they close the cycles) and rank last.
  std::stable_partition(by_length.begin(), by_length.end(),
                        [&](const auto& x) { return !through_air.count(x.second); });
  std::map<std::uint32_t, std::vector<std::pair<float, std::array<std::uint32_t, 2>>>> closing;
  for (const auto& [length, e] : by_length)
    if (!forest.unite(e[0], e[1]) && !sk.nodes[e[0]].vertices.empty())
      closing[mesh_parts.find(sk.nodes[e[0]].vertices.front())].push_back(
          {through_air.count(e) ? -length : length, e});
  for (auto& [root, list] : closing) {
    auto g = static_cast<std::size_t>(std::max(0LL, (2 - chi[root]) / 2));
    if (const auto it = sheet_cycles.find(root); it != sheet_cycles.end()) g -= std::min(g, it->second);
    std::sort(list.rbegin(), list.rend());
    for (std::size_t k = g; k < list.size(); ++k) edges.erase(list[k].second);
  }
}

// The tip node of a curve leaf (SkeletonOptions::extend_leaves, in build()); nothing when `leaf`
// is not a curve leaf of `adjacency` with at least two vertices.
void extend_tip(Skeleton& sk, EdgeSet& edges, std::vector<std::uint32_t>& node_of_vertex, const Surface& surface,
                std::uint32_t leaf, const std::vector<std::vector<std::uint32_t>>& adjacency) {
  const Mesh& original = surface.original;
  if (adjacency[leaf].size() != 1 || sk.nodes[leaf].sheet || sk.nodes[leaf].vertices.size() < 2) return;
  const glm::vec3 p = sk.nodes[leaf].position, q = sk.nodes[adjacency[leaf].front()].position;
  const float len = glm::length(p - q);
  if (!(len > 0.0f)) return;
  const glm::vec3 dir = (p - q) / len;
  std::uint32_t far_vertex = sk.nodes[leaf].vertices.front();
  for (std::uint32_t k : sk.nodes[leaf].vertices)
    if (glm::dot(original.positions[k] - p, dir) > glm::dot(original.positions[far_vertex] - p, dir)) far_vertex = k;
  const glm::vec3 tip = surface.centre[far_vertex];
  if (glm::dot(tip - p, dir) <= sk.nodes[leaf].radius || !surface.bvh.inside(tip) ||
      surface.bvh.segment_blocked(p, tip))
    return;
  const glm::vec3 mid = 0.5f * (p + tip);
  std::vector<std::uint32_t> moved, kept;
  for (std::uint32_t k : sk.nodes[leaf].vertices)
    (glm::dot(original.positions[k] - mid, dir) > 0.0f && surface.sees(k, tip) ? moved : kept).push_back(k);
  if (moved.empty() || kept.empty()) return;
  // The node sits where every node sits, at the centre of its vertices' region (the mean of
  // their centre points), when that is inside and joined to the leaf through the solid; the tip
  // itself only decided that there is room. At the tip, the extreme vertex's centre point lies
  // within SDF/2 of the surface, nearer than any node: over CGAL's set, tip nodes there ended
  // up to 9 % of the diagonal beyond CGAL's leaves (diplodocus's and the hand's missed ones).
  glm::dvec3 mean(0.0);
  for (std::uint32_t k : moved) mean += glm::dvec3(surface.centre[k]);
  glm::vec3 at(mean / static_cast<double>(moved.size()));
  if (!surface.bvh.inside(at) || surface.bvh.segment_blocked(p, at)) at = tip;
  sk.nodes[leaf].vertices = std::move(kept);
  sk.nodes[leaf].radius = surface.radius(p, sk.nodes[leaf].vertices);
  Node node;
  node.position = at;
  node.vertices = std::move(moved);
  node.radius = surface.radius(at, node.vertices);
  const auto id = static_cast<std::uint32_t>(sk.nodes.size());
  for (std::uint32_t k : node.vertices) node_of_vertex[k] = id;
  sk.nodes.push_back(std::move(node));
  add_edge(edges, leaf, id);
}

// Curve edges follow the limb between their nodes (s11shape). Grouping leaves nodes up to the
// grouping distance apart (a bear: 8 nodes), and a straight edge between two of them is a chord
// of the tube, off its centre wherever the limb bends (over CGAL's set the chords, not the
// nodes, were most of the distance to CGAL's curves: bear 0.56 % of the diagonal at the nodes,
// 2.59 % along the edges). Each curve edge (a, b) longer than two local radii is cut into
// cross-sections one local radius r = (r_a + r_b) / 2 apart: the vertices of a and b that
// project between them along ab, whose centre points lie within r of the segment (the tube of
// this edge, not another branch of a junction), go to the section nearest their projection,
// and a section node sits at the mean of its vertices' centre points (the centre of that
// cross-section, as the embedding refinement places every node). A section keeps the
// vertices that see it and needs three; the edge becomes the chain through its sections
// only when every section node is inside and every link of the chain stays inside, else it
// is left as it was. a and b keep their positions and at least one vertex each. Each vertex
// moves at most once; a chain has the edge's ends, so leaves, junctions and cycles are
// unchanged.
void add_sections(Skeleton& sk, EdgeSet& edges, std::vector<std::uint32_t>& node_of_vertex, std::vector<std::uint8_t>& moved,
                  const Surface& surface, const std::vector<std::array<std::uint32_t, 2>>& current) {
  const Mesh& original = surface.original;
  for (const auto& e : current) {
  const std::uint32_t a = e[0], b = e[1];
  if (sk.nodes[a].sheet || sk.nodes[b].sheet) continue;
  const glm::vec3 pa = sk.nodes[a].position, pb = sk.nodes[b].position;
  const float len = glm::length(pb - pa);
  const float r = 0.5f * (sk.nodes[a].radius + sk.nodes[b].radius);
  if (!(r > 0.0f) || !(len > 2.0f * r)) continue;
  const glm::vec3 dir = (pb - pa) / len;
  const int sections = static_cast<int>(std::lround(len / r));
  const float spacing = len / static_cast<float>(sections);
  std::vector<std::vector<std::uint32_t>> slice(static_cast<std::size_t>(sections));
  std::size_t left_a = sk.nodes[a].vertices.size(), left_b = sk.nodes[b].vertices.size();
  for (const std::uint32_t end : {a, b})
    for (std::uint32_t k : sk.nodes[end].vertices) {
      if (moved[k]) continue;
      const float t = glm::dot(original.positions[k] - pa, dir);
      const int j = static_cast<int>(std::lround(t / spacing));
      if (j < 1 || j >= sections) continue;
      const glm::vec3 c = surface.centre[k];
      const float tc = std::clamp(glm::dot(c - pa, dir), 0.0f, len);
      if (glm::length(c - (pa + tc * dir)) > r) continue;
      slice[static_cast<std::size_t>(j)].push_back(k);
    }
  std::vector<std::pair<glm::vec3, std::vector<std::uint32_t>>> chain;
  for (const auto& part : slice) {
    if (part.size() < 3) continue;
    glm::dvec3 mean(0.0);
    for (std::uint32_t k : part) mean += glm::dvec3(surface.centre[k]);
    const glm::vec3 at(mean / static_cast<double>(part.size()));
    if (!surface.bvh.inside(at)) continue;
    std::vector<std::uint32_t> seeing;
    for (std::uint32_t k : part)
      if (surface.sees(k, at)) seeing.push_back(k);
    if (seeing.size() < 3) continue;
    chain.push_back({at, std::move(seeing)});
  }
  if (chain.empty()) continue;
  for (const auto& [at, part] : chain)
    for (std::uint32_t k : part) (node_of_vertex[k] == a ? left_a : left_b)--;
  bool ok = left_a > 0 && left_b > 0;
  glm::vec3 previous = pa;
  for (const auto& [at, part] : chain) {
    ok = ok && !surface.bvh.segment_blocked(previous, at);
    previous = at;
  }
  ok = ok && !surface.bvh.segment_blocked(previous, pb);
  if (!ok) continue;
  std::set<std::uint32_t> leaving;
  for (const auto& [at, part] : chain) leaving.insert(part.begin(), part.end());
  for (const std::uint32_t end : {a, b}) {
    std::vector<std::uint32_t>& v = sk.nodes[end].vertices;
    v.erase(std::remove_if(v.begin(), v.end(), [&](std::uint32_t k) { return leaving.count(k) > 0; }), v.end());
    sk.nodes[end].radius = surface.radius(sk.nodes[end].position, v);
  }
  edges.erase(e);
  std::uint32_t from = a;
  for (auto& [at, part] : chain) {
    Node node;
    node.position = at;
    node.radius = surface.radius(at, part);
    const auto id = static_cast<std::uint32_t>(sk.nodes.size());
    for (std::uint32_t k : part) node_of_vertex[k] = id, moved[k] = 1;
    node.vertices = std::move(part);
    sk.nodes.push_back(std::move(node));
    add_edge(edges, from, id);
    from = id;
  }
  add_edge(edges, from, b);
  }
}

// The terminal branch from curve leaf `leaf`: the leaf, its chain of degree-2 curve nodes, and
// last the node where the chain ends (of another degree, a sheet node, or the leaf again).
std::vector<std::uint32_t> branch_from(const Skeleton& sk, const std::vector<std::vector<std::uint32_t>>& adjacency,
                                       std::uint32_t leaf) {
  std::vector<std::uint32_t> branch{leaf};
  std::uint32_t prev = leaf, cur = adjacency[leaf].front();
  while (adjacency[cur].size() == 2 && !sk.nodes[cur].sheet && cur != leaf) {
    branch.push_back(cur);
    const std::uint32_t next = adjacency[cur][0] == prev ? adjacency[cur][1] : adjacency[cur][0];
    prev = cur, cur = next;
  }
  branch.push_back(cur);
  return branch;
}

// Terminal branches covered by the rest of the skeleton: a branch (a leaf and the chain of
// degree-2 curve nodes up to the first node of degree >= 3) whose every node's ball lies in
// what the rest of the skeleton stands for (the other curve nodes' balls swept along the
// curve edges between them, as the protrusion step reads the skeleton) describes no
// part of the solid that the rest does not; it is a bump of the surface or a spur beside a
// limb's own curve, not a limb. A ball counts as covered when its centre and 26 points on its
// sphere (the directions of a 3x3x3 grid) each lie in that union. (At first only the
// junction's ball counted; spurs beside a limb, whose balls the neighbouring nodes of the
// limb cover together but no single ball does, stayed. Then the edges were not swept: a
// ball centred on a limb's curve between two nodes lies in neither node's ball, and 14 spurs
// over CGAL's data set stayed for that.) Such branches are merged into their
// junction, the one that reaches least out of the union first, while the junction keeps
// degree >= 3 (a junction never becomes a leaf, so no limb is shortened step by step).
void prune_covered_branches(Skeleton& sk, EdgeSet& edges, std::vector<std::uint32_t>& node_of_vertex) {
  std::vector<std::uint8_t> dead(sk.nodes.size(), 0);
  for (bool changed = true; changed;) {
    changed = false;
    std::vector<std::vector<std::uint32_t>> adjacency(sk.nodes.size());
    for (const auto& e : edges) adjacency[e[0]].push_back(e[1]), adjacency[e[1]].push_back(e[0]);
    struct Branch {
      float excess;  // how far the branch's balls reach out of the other nodes' (< 0: inside)
      std::uint32_t leaf, junction;
      std::vector<std::uint32_t> path;
    };
    std::vector<std::uint8_t> on_path(sk.nodes.size(), 0);
    std::vector<Branch> branches;
    for (std::uint32_t leaf = 0; leaf < sk.nodes.size(); ++leaf) {
      if (dead[leaf] || adjacency[leaf].size() != 1 || sk.nodes[leaf].sheet) continue;
      std::vector<std::uint32_t> path = branch_from(sk, adjacency, leaf);
      const std::uint32_t cur = path.back();
      path.pop_back();
      if (adjacency[cur].size() < 3 || sk.nodes[cur].sheet) continue;
      for (std::uint32_t k : path) on_path[k] = 1;
      float excess = -std::numeric_limits<float>::infinity();
      for (std::size_t i = 0; i < path.size() && excess < 0.0f; ++i) {
        const Node& a = sk.nodes[path[i]];
        // The other curve nodes and the curve edges between them whose balls meet this
        // one's: only they can cover it.
        auto other = [&](std::uint32_t m) {
          return !on_path[m] && !dead[m] && !sk.nodes[m].sheet && !sk.nodes[m].vertices.empty();
        };
        std::vector<std::uint32_t> near;
        for (std::uint32_t m = 0; m < sk.nodes.size(); ++m)
          if (other(m) && glm::length(sk.nodes[m].position - a.position) < a.radius + sk.nodes[m].radius)
            near.push_back(m);
        std::vector<std::array<std::uint32_t, 2>> near_edges;
        for (const auto& e : edges)
          if (other(e[0]) && other(e[1]) &&
              distance_to_segment(a.position, sk.nodes[e[0]].position, sk.nodes[e[1]].position) <
                  a.radius + std::max(sk.nodes[e[0]].radius, sk.nodes[e[1]].radius))
            near_edges.push_back(e);
        for (int dx = -1; dx <= 1 && excess < 0.0f; ++dx)
          for (int dy = -1; dy <= 1 && excess < 0.0f; ++dy)
            for (int dz = -1; dz <= 1 && excess < 0.0f; ++dz) {
              const glm::vec3 d(static_cast<float>(dx), static_cast<float>(dy), static_cast<float>(dz));
              const glm::vec3 q = d == glm::vec3(0.0f) ? a.position : a.position + a.radius * glm::normalize(d);
              float outside = std::numeric_limits<float>::infinity();
              for (std::uint32_t m : near)
                outside = std::min(outside, glm::length(q - sk.nodes[m].position) - sk.nodes[m].radius);
              for (const auto& e : near_edges)
                outside = std::min(outside, outside_swept_ball(q, sk.nodes[e[0]], sk.nodes[e[1]]));
              excess = std::max(excess, outside);
            }
      }
      for (std::uint32_t k : path) on_path[k] = 0;
      if (excess < 0.0f) branches.push_back({excess, leaf, cur, std::move(path)});
    }
    std::sort(branches.begin(), branches.end(), [](const Branch& a, const Branch& b) {
      return a.excess != b.excess ? a.excess < b.excess : a.leaf < b.leaf;
    });
    std::vector<std::size_t> degree(sk.nodes.size());
    for (std::uint32_t k = 0; k < sk.nodes.size(); ++k) degree[k] = adjacency[k].size();
    for (const Branch& b : branches) {
      if (degree[b.junction] < 3 || dead[b.leaf]) continue;
      std::uint32_t prev = b.junction;
      for (auto it = b.path.rbegin(); it != b.path.rend(); ++it) {
        edges.erase({std::min(prev, *it), std::max(prev, *it)});
        prev = *it;
      }
      --degree[b.junction];
      Node& j = sk.nodes[b.junction];
      for (std::uint32_t k : b.path) {
        for (std::uint32_t v : sk.nodes[k].vertices) node_of_vertex[v] = b.junction;
        j.vertices.insert(j.vertices.end(), sk.nodes[k].vertices.begin(), sk.nodes[k].vertices.end());
        sk.nodes[k].vertices.clear();
        dead[k] = 1;
      }
      std::sort(j.vertices.begin(), j.vertices.end());
      changed = true;
    }
  }
  // Remove the merged nodes and renumber.
  if (std::find(dead.begin(), dead.end(), 1) != dead.end())
    edges = renumbered(edges, remove_nodes(sk, dead, node_of_vertex));
}

// Terminal branches that fold, or run beside another limb. A leg that contracted to a flat
// ribbon collapses to its two rims, joined at the hoof; placed at their vertices' centre points
// the rims fall onto one line, and with the loop cut at the top the leg's chain runs down to
// the hoof and back up, its leaf at mid-leg (CGAL's cow and bull). A rim can also hang from a
// junction beside its limb's chain as a strand of its own, a leaf in the middle of the limb
// (the armadillo's legs). A branch (a leaf and its chain of degree-2 curve nodes up to the
// first node of another degree) is unfolded where a run of its nodes from the leaf lies beside
// the rest of the branch or beside another curve edge of its component (none with an end on
// the branch before its last node). A node x lies beside an edge when it projects strictly
// between the edge's ends, its centre is inside the balls swept along the edge, and the edge
// passes through x's own ball: both ways, since a thin foot bent back along a thick leg lies in
// the leg's balls but the leg's axis is not in the foot's (triceratops), and a toe beside a
// foot is thinner than the foot. A node that coincides with an inner node of the rest of its
// branch (each inside the other's ball, that node the rest's nearest) lies beside it too. The
// longest such run is threaded into those edges, each node into the edge it lies deepest in
// (outside_swept_ball over the radius there) in the order they project onto it: the node
// where the branch turned becomes the leaf, and a strand that lies beside its limb all the way
// to the junction goes into the limb, the junction losing that branch. Along one chain a node
// lies past the end of the next edge, never strictly beside it (a tube's axis cannot bend
// tighter than its radius), so a limb's own tip stays: the rest's first node has no edge
// beyond it. Each node threaded takes away one edge of the branch and adds one, so the cycles
// stay, and the nodes stay in their component. The new edges must be shorter than those they
// replace (so no node is threaded back and forth) and stay inside, else the branch stays.
// Repeated while a branch changes (its new leaf can start another run); within a round no node
// is used twice. This runs after the cross-section nodes: before them a limb's curve is a
// chord between grouped nodes, and the returning rim lies off it near the hoof (the bull's
// folded leg then stayed), while earlier it moved bunny00's ear leaf 0.073 -> 0.086 of
// the diagonal from its tip. Merging a strand's nodes into the limb's nearer nodes, instead of
// threading them, gave cleaner chains but moved bunny00's ear leaf past the test's bound.
void unfold_branches(Skeleton& sk, EdgeSet& edges, const Surface& surface) {
  std::size_t unfolded = 0;
  for (std::size_t round = 0; round < sk.nodes.size(); ++round) {
    std::vector<std::vector<std::uint32_t>> adjacency(sk.nodes.size());
    UnionFind parts(sk.nodes.size());
    for (const auto& e : edges) {
      adjacency[e[0]].push_back(e[1]), adjacency[e[1]].push_back(e[0]);
      parts.unite(e[0], e[1]);
    }
    std::vector<std::array<std::uint32_t, 2>> curve_edges;
    for (const auto& e : edges)
      if (!sk.nodes[e[0]].sheet && !sk.nodes[e[1]].sheet) curve_edges.push_back(e);
    std::vector<std::uint8_t> touched(sk.nodes.size(), 0);
    bool changed = false;
    for (std::uint32_t leaf = 0; leaf < sk.nodes.size(); ++leaf) {
      if (adjacency[leaf].size() != 1 || sk.nodes[leaf].sheet || touched[leaf]) continue;
      const std::vector<std::uint32_t> full = branch_from(sk, adjacency, leaf);
      const std::uint32_t cur = full.back();
      if (sk.nodes[cur].sheet || std::any_of(full.begin(), full.end(), [&](std::uint32_t x) { return touched[x]; }))
        continue;
      // The curve edges of the rest of the skeleton near the branch (none with an end on the
      // branch before its last node), in the branch's component.
      std::set<std::uint32_t> own(full.begin(), full.end() - 1);
      glm::vec3 lo(std::numeric_limits<float>::max()), hi(std::numeric_limits<float>::lowest());
      float widest = 0.0f;
      for (std::uint32_t x : full) {
        lo = glm::min(lo, sk.nodes[x].position), hi = glm::max(hi, sk.nodes[x].position);
        widest = std::max(widest, sk.nodes[x].radius);
      }
      std::vector<std::array<std::uint32_t, 2>> others;
      for (const auto& e : curve_edges) {
        if (own.count(e[0]) || own.count(e[1]) || touched[e[0]] || touched[e[1]] || parts.find(e[0]) != parts.find(cur))
          continue;
        const glm::vec3 pa = sk.nodes[e[0]].position, pb = sk.nodes[e[1]].position;
        const float r = std::max(sk.nodes[e[0]].radius, sk.nodes[e[1]].radius) + widest;
        if (glm::all(glm::lessThanEqual(glm::min(pa, pb) - r, hi)) && glm::all(glm::greaterThanEqual(glm::max(pa, pb) + r, lo)))
          others.push_back(e);
      }
      // Where node x lies deepest beside an edge: (index: i for the branch's edge (full[i],
      // full[i + 1]) with i >= from, full.size() + j for others[j]; t; depth), or index SIZE_MAX
      // when beside none.
      struct Spot {
        std::size_t edge = SIZE_MAX;
        float t = 0.0f, depth = 0.0f;
      };
      auto beside = [&](std::uint32_t x, std::size_t from) {
        Spot best;
        const glm::vec3 p = sk.nodes[x].position;
        auto consider = [&](std::size_t index, const Node& a, const Node& b) {
          const float t = segment_parameter(p, a.position, b.position);
          if (t <= 0.0f || t >= 1.0f) return;
          // Both ways: x's centre inside the balls swept along the edge, and the edge through
          // x's own ball (a thin foot bent back along a thick leg lies in the leg's balls, but
          // the leg's axis is not in the foot's).
          const float depth = std::max(outside_swept_ball(p, a, b) / (a.radius + t * (b.radius - a.radius)),
                                       distance_to_segment(p, a.position, b.position) / sk.nodes[x].radius - 1.0f);
          if (depth < 0.0f && (best.edge == SIZE_MAX || depth < best.depth)) best = {index, t, depth};
        };
        for (std::size_t i = from; i + 1 < full.size(); ++i) consider(i, sk.nodes[full[i]], sk.nodes[full[i + 1]]);
        for (std::size_t j = 0; j < others.size(); ++j)
          consider(full.size() + j, sk.nodes[others[j][0]], sk.nodes[others[j][1]]);
        // Or x coincides with an inner node y of the rest of its branch, that branch's node
        // nearest to it (each inside the other's ball), where it projects onto neither of y's
        // edges strictly: x goes next to y. (The rest's first node has no edge beyond it: a
        // leaf past its neighbour, a limb's tip, is never beside.)
        if (best.edge == SIZE_MAX) {
          std::size_t j = from;
          for (std::size_t i = from; i < full.size(); ++i)
            if (glm::length(sk.nodes[full[i]].position - p) < glm::length(sk.nodes[full[j]].position - p)) j = i;
          const float d = glm::length(sk.nodes[full[j]].position - p);
          const float depth = std::max(d / sk.nodes[full[j]].radius, d / sk.nodes[x].radius) - 1.0f;
          if (j > from && j + 1 < full.size() && depth < 0.0f) best = {j - 1, 1.0f, depth};
        }
        return best;
      };
      // The longest run full[0..m) whose every node lies beside an edge of full[m..] or of the
      // rest of the skeleton; it may be the whole branch (a strand beside another limb, hanging
      // from the junction), never the junction.
      std::size_t m = 0;
      while (m + 1 < full.size()) {
        bool all = true;
        for (std::size_t i = 0; i <= m && all; ++i) all = beside(full[i], m + 1).edge != SIZE_MAX;
        if (!all) break;
        ++m;
      }
      if (m == 0) continue;
      std::vector<std::vector<std::pair<float, std::uint32_t>>> into(full.size() + others.size());
      for (std::size_t i = 0; i < m; ++i) {
        const Spot s = beside(full[i], m);
        into[s.edge].push_back({s.t, full[i]});
      }
      // The new chains: the rest of the branch with its own nodes threaded in, and each other
      // edge that takes nodes.
      std::vector<std::vector<std::uint32_t>> chains(1);
      for (std::size_t i = m; i < full.size(); ++i) {
        chains[0].push_back(full[i]);
        std::sort(into[i].begin(), into[i].end());
        for (const auto& [t, x] : into[i]) chains[0].push_back(x);
      }
      std::vector<std::array<std::uint32_t, 2>> hosts;
      for (std::size_t j = 0; j < others.size(); ++j) {
        auto& in = into[full.size() + j];
        if (in.empty()) continue;
        std::sort(in.begin(), in.end());
        hosts.push_back(others[j]);
        chains.push_back({others[j][0]});
        for (const auto& [t, x] : in) chains.back().push_back(x);
        chains.back().push_back(others[j][1]);
      }
      // Shorter than what it replaces (so no two nodes trade places back and forth), and inside.
      auto length = [&](const std::vector<std::uint32_t>& path) {
        float sum = 0.0f;
        for (std::size_t i = 0; i + 1 < path.size(); ++i)
          sum += glm::length(sk.nodes[path[i]].position - sk.nodes[path[i + 1]].position);
        return sum;
      };
      float before = length(full), after = 0.0f;
      for (const auto& h : hosts) before += length({h[0], h[1]});
      for (const auto& c : chains) after += length(c);
      if (!(after < before)) continue;
      bool inside = true;
      for (const auto& c : chains)
        for (std::size_t i = 0; i + 1 < c.size() && inside; ++i)
          inside = !surface.bvh.segment_blocked(sk.nodes[c[i]].position, sk.nodes[c[i + 1]].position);
      if (!inside) continue;
      for (std::size_t i = 0; i + 1 < full.size(); ++i)
        edges.erase({std::min(full[i], full[i + 1]), std::max(full[i], full[i + 1])});
      for (const auto& h : hosts) edges.erase(h), touched[h[0]] = touched[h[1]] = 1;
      for (const auto& c : chains)
        for (std::size_t i = 0; i + 1 < c.size(); ++i) add_edge(edges, c[i], c[i + 1]);
      for (std::uint32_t x : full) touched[x] = 1;
      unfolded += m;
      changed = true;
    }
    if (!changed) break;
  }
  log_debug("skeleton: " + std::to_string(unfolded) + " nodes of branches threaded into the limb they lie beside");
}

// Eigenvalues of a symmetric positive semi-definite 3x3 matrix, largest first (trigonometric
// solution).
std::array<double, 3> symmetric_eigenvalues(const glm::dmat3& a) {
  const double p1 = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
  const double q = (a[0][0] + a[1][1] + a[2][2]) / 3.0;
  const double p2 = (a[0][0] - q) * (a[0][0] - q) + (a[1][1] - q) * (a[1][1] - q) +
                    (a[2][2] - q) * (a[2][2] - q) + 2.0 * p1;
  const double p = std::sqrt(p2 / 6.0);
  if (!(p > 0.0)) return {q, q, q};
  const glm::dmat3 b = (1.0 / p) * (a - q * glm::dmat3(1.0));
  const double r = std::clamp(glm::determinant(b) / 2.0, -1.0, 1.0);
  const double phi = std::acos(r) / 3.0;
  const double e1 = q + 2.0 * p * std::cos(phi);
  const double e3 = q + 2.0 * p * std::cos(phi + 2.0943951023931953);
  return {e1, 3.0 * q - e1 - e3, e3};
}

// Covariance of points (divided by their count) and their mean.
template <class Points>
std::pair<glm::dmat3, glm::dvec3> covariance(const Points& points) {
  glm::dvec3 m(0.0);
  for (const glm::dvec3& p : points) m += p;
  m /= static_cast<double>(std::max<std::size_t>(1, points.size()));
  glm::dmat3 c(0.0);
  for (const glm::dvec3& p : points) c += glm::outerProduct(p - m, p - m);
  return {c / static_cast<double>(std::max<std::size_t>(1, points.size())), m};
}

// `region` split into pieces of connected vertices whose centre points share a cell of
// kRegionCell * diag (diag: the mesh's bounding-box diagonal; in the order of their first
// vertex), and whether it is mostly flat: flat pieces of >= 4 vertices hold over half of those
// pieces' vertices. A piece is flat when
//   - its centre points spread in two directions (lambda_2 / lambda_1 > kFlatRatio), and
//   - the region's centre points within twice the piece's thickness t of its mean spread in
//     their second principal direction over more than t (sqrt(12 lambda_2), a uniform
//     spread's length). That is "wider than thick": a plate's mid-surface fills the ball in
//     two directions (a disc: 3.5 t across; at the plate's rim half a disc: 1.8 t), a limb's
//     centre points lie along its axis (an elliptic limb's, along a segment that is longer
//     than the limb is thick only where the section is over twice as wide as thick). The cell
//     alone cannot say it: it caps the first spread at the cell, so a limb about as thick as
//     the cell looks as round as a plate (the armadillo's forearm became a sheet). The thickness
//     t is twice the mean distance from a vertex to its centre point (the SDF where the
//     centre point came from it).
struct Pieces {
  std::vector<std::vector<std::uint32_t>> pieces;
  bool mostly_flat = false;
};

// The grid cell of side `cell` that holds q.
std::array<std::int64_t, 3> cell_key(const glm::dvec3& q, double cell) {
  return std::array<std::int64_t, 3>{static_cast<std::int64_t>(std::floor(q.x / cell)),
                                     static_cast<std::int64_t>(std::floor(q.y / cell)),
                                     static_cast<std::int64_t>(std::floor(q.z / cell))};
}

Pieces split_region(const Surface& surface, double diag, const std::vector<std::uint32_t>& region) {
  const Mesh& original = surface.original;
  const double cell = kRegionCell * diag;
  std::map<std::array<std::int64_t, 3>, std::uint32_t> cell_index;
  std::vector<std::uint32_t> cell_of(region.size());
  std::map<std::uint32_t, std::uint32_t> slot;  // vertex -> index in region
  for (std::uint32_t i = 0; i < region.size(); ++i) {
    const std::array<std::int64_t, 3> key = cell_key(glm::dvec3(surface.centre[region[i]]), cell);
    cell_of[i] = cell_index.try_emplace(key, static_cast<std::uint32_t>(cell_index.size())).first->second;
    slot[region[i]] = i;
  }
  UnionFind pieces(region.size());
  for (const Triangle& t : original.triangles)
    for (int e = 0; e < 3; ++e) {
      const auto a = slot.find(t[e]), b = slot.find(t[(e + 1) % 3]);
      if (a != slot.end() && b != slot.end() && cell_of[a->second] == cell_of[b->second])
        pieces.unite(a->second, b->second);
    }
  std::map<std::uint32_t, std::vector<std::uint32_t>> piece_members;
  std::vector<std::uint32_t> piece_order;
  for (std::uint32_t i = 0; i < region.size(); ++i) {
    auto [it, inserted] = piece_members.try_emplace(pieces.find(i));
    if (inserted) piece_order.push_back(pieces.find(i));
    it->second.push_back(region[i]);
  }
  // The region's centre points on a grid of the same cell, for the balls around the pieces.
  std::map<std::array<std::int64_t, 3>, std::vector<std::uint32_t>> region_cells;
  for (std::uint32_t k : region) region_cells[cell_key(glm::dvec3(surface.centre[k]), cell)].push_back(k);
  double flat = 0.0, total = 0.0;
  for (std::uint32_t r : piece_order) {
    const std::vector<std::uint32_t>& piece = piece_members[r];
    if (piece.size() < 4) continue;
    total += static_cast<double>(piece.size());
    std::vector<glm::dvec3> points;
    double thickness = 0.0;
    for (std::uint32_t k : piece) {
      points.push_back(glm::dvec3(surface.centre[k]));
      thickness += 2.0 * glm::length(glm::dvec3(original.positions[k]) - points.back());
    }
    thickness /= static_cast<double>(piece.size());
    const std::pair<glm::dmat3, glm::dvec3> piece_cov = covariance(points);
    const glm::dvec3 mean = piece_cov.second;  // a plain variable: lambdas below capture it
    const std::array<double, 3> e = symmetric_eigenvalues(piece_cov.first);
    if (!(e[0] > 0.0) || !(e[1] / e[0] > kFlatRatio)) continue;
    const double reach = 2.0 * thickness;
    points.clear();
    const auto lo = cell_key(mean - glm::dvec3(reach), cell), hi = cell_key(mean + glm::dvec3(reach), cell);
    const auto gather = [&](const std::vector<std::uint32_t>& members_of_cell) {
      for (std::uint32_t k : members_of_cell)
        if (glm::length(glm::dvec3(surface.centre[k]) - mean) <= reach) points.push_back(glm::dvec3(surface.centre[k]));
    };
    const double box_cells = static_cast<double>(hi[0] - lo[0] + 1) * static_cast<double>(hi[1] - lo[1] + 1) *
                             static_cast<double>(hi[2] - lo[2] + 1);
    if (box_cells > static_cast<double>(region_cells.size())) {
      // A ball wider than the region's cells (a thick part): visit the occupied cells instead.
      for (const auto& [key, members_of_cell] : region_cells)
        if (key[0] >= lo[0] && key[0] <= hi[0] && key[1] >= lo[1] && key[1] <= hi[1] && key[2] >= lo[2] && key[2] <= hi[2])
          gather(members_of_cell);
    } else {
      for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
        for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
          for (std::int64_t z = lo[2]; z <= hi[2]; ++z)
            if (const auto it = region_cells.find({x, y, z}); it != region_cells.end()) gather(it->second);
    }
    if (points.size() < 4) continue;
    const double spread = std::sqrt(12.0 * std::max(0.0, symmetric_eigenvalues(covariance(points).first)[1]));
    if (spread > thickness) flat += static_cast<double>(piece.size());
  }
  Pieces out;
  for (std::uint32_t r : piece_order) out.pieces.push_back(std::move(piece_members[r]));
  out.mostly_flat = total > 0.0 && flat > 0.5 * total;
  return out;
}

// Protrusions that the contraction merged whole (s11branch): a thin part (an ear, a foot, a
// tusk) that contracted into a node of the body and whose vertices see that node, so the
// regions above (vertices that see no curve node) never gave it a branch. The skeleton stands
// for the union of its curve nodes' balls (position, radius) swept along its curve edges
// (radius interpolated along the edge), the union the pruning of terminal branches asks about.
// A vertex whose centre point lies outside that union lies on a part of the solid that the
// skeleton does not reach. A connected region of such vertices is a protrusion when
//   - it reaches farther from its base (the vertices just outside the region: the distance
//     from its farthest vertex to the nearest base vertex) than the base's own radius (from
//     the base's centroid): a bump on its base reaches at most a hemisphere, a band along a
//     flattened body or a plate's rim is as wide along its boundary as it is far from it.
//     Measured from the base's centroid instead, the end band of a thin-walled pipe passed
//     (its base circles the axis and the centroid lies on the axis);
//   - the ball of the region (mean centre point, mean vertex radius |u - centre| = SDF/2)
//     does not touch the union either (a band beside a spine has its mean near the spine);
//   - its base has no sheet vertex (a region beside a sheet continues that plate: the C plate).
// It gets curve nodes by the rules of the unseen regions: one node at the mean of its centre
// points when at least half of its vertices see it, joined to the nearest curve node it sees
// through the solid; else one per piece unless the pieces are mostly flat. A vertex moves to
// the new node when it sees it and its node keeps another vertex; a region that gets no node
// stays as it is. Up to three rounds (the union grows with the new nodes); then the new leaves
// get their tip nodes as above. Every new node is inside and every new edge is a segment
// inside from a new leaf to the skeleton, so cycles and sheets are unchanged. This runs after
// the cross-section nodes, so a branch joins the curve near where the protrusion leaves it (a
// heel joins the ankle's section, not the foot's leaf, which homer's foot lost otherwise),
// and the new edges get their own cross-sections. No new constant.
void add_protrusion_branches(Skeleton& sk, EdgeSet& edges, std::vector<std::uint32_t>& node_of_vertex,
                             std::vector<std::uint8_t>& moved, const Surface& surface, const SkeletonOptions& options) {
  const Mesh& original = surface.original;
  const std::size_t n = original.positions.size();
  const double diag = bounding_box(original.positions).diagonal();
  const std::size_t first_new = sk.nodes.size();
  // Mesh neighbours of each vertex (CSR).
  std::vector<std::uint32_t> ring_start(n + 1, 0), ring;
  {
    std::vector<std::array<std::uint32_t, 2>> pairs;
    for (const Triangle& t : original.triangles)
      for (int i = 0; i < 3; ++i) pairs.push_back({t[i], t[(i + 1) % 3]}), pairs.push_back({t[(i + 1) % 3], t[i]});
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    for (const auto& pr : pairs) ++ring_start[pr[0] + 1];
    for (std::size_t k = 0; k < n; ++k) ring_start[k + 1] += ring_start[k];
    ring.reserve(pairs.size());
    for (const auto& pr : pairs) ring.push_back(pr[1]);
  }
  std::vector<float> vertex_radius(n);
  for (std::uint32_t k = 0; k < n; ++k)
    vertex_radius[k] = glm::length(original.positions[k] - surface.centre[k]);
  for (int round = 0; round < 3; ++round) {
    std::vector<std::vector<std::uint32_t>> adjacency(sk.nodes.size());
    std::vector<std::array<std::uint32_t, 2>> curve_edges;
    for (const auto& e : edges) {
      adjacency[e[0]].push_back(e[1]), adjacency[e[1]].push_back(e[0]);
      if (!sk.nodes[e[0]].sheet && !sk.nodes[e[1]].sheet) curve_edges.push_back(e);
    }
    auto touches_edge = [&](const glm::vec3& p, float r, std::uint32_t a, std::uint32_t b) {
      return outside_swept_ball(p, sk.nodes[a], sk.nodes[b]) <= r;
    };
    // Does the ball (p, r) touch the skeleton's union? `hint`'s node and edges first.
    auto touches = [&](const glm::vec3& p, float r, std::uint32_t hint) {
      if (hint != UINT32_MAX) {
        if (glm::length(p - sk.nodes[hint].position) <= sk.nodes[hint].radius + r) return true;
        for (std::uint32_t d : adjacency[hint])
          if (!sk.nodes[d].sheet && touches_edge(p, r, hint, d)) return true;
      }
      for (const Node& node : sk.nodes)
        if (!node.sheet && glm::length(p - node.position) <= node.radius + r) return true;
      for (const auto& e : curve_edges)
        if (touches_edge(p, r, e[0], e[1])) return true;
      return false;
    };
    std::vector<std::uint32_t> stamp(n, 0);  // boundary vertices seen, per region (root + 1)
    std::vector<std::uint8_t> outside(n, 0);
    parallel_for(n, [&](std::size_t begin, std::size_t end) {
      for (auto k = static_cast<std::uint32_t>(begin); k < end; ++k) {
        const std::uint32_t c = node_of_vertex[k];
        outside[k] = c != UINT32_MAX && !sk.nodes[c].sheet && !touches(surface.centre[k], 0.0f, c);
      }
    });
    UnionFind regions(n);
    for (const Triangle& t : original.triangles)
      for (int i = 0; i < 3; ++i) {
        const std::uint32_t a = t[i], b = t[(i + 1) % 3];
        if (outside[a] && outside[b]) regions.unite(a, b);
      }
    std::map<std::uint32_t, std::vector<std::uint32_t>> region_members;  // root -> vertices (ascending)
    std::vector<std::uint32_t> region_order;
    for (std::uint32_t k = 0; k < n; ++k)
      if (outside[k]) {
        auto [it, inserted] = region_members.try_emplace(regions.find(k));
        if (inserted) region_order.push_back(regions.find(k));
        it->second.push_back(k);
      }
    // A new curve leaf for `part` (the region step's add_node on the skeleton's nodes).
    auto add_leaf = [&](const std::vector<std::uint32_t>& part) {
      std::optional<Surface::RegionNode> found = surface.region_node(part);
      if (!found) return false;
      const glm::vec3 p = found->point;
      std::vector<std::uint32_t>& seeing = found->seeing;
      std::vector<std::pair<std::uint32_t, glm::vec3>> curve;
      const std::uint32_t comp = surface.component[part.front()];  // a region is connected
      for (std::uint32_t c = 0; c < sk.nodes.size(); ++c)
        if (!sk.nodes[c].sheet && !sk.nodes[c].vertices.empty() &&
            surface.component[sk.nodes[c].vertices.front()] == comp)
          curve.push_back({c, sk.nodes[c].position});
      const std::uint32_t attach = surface.nearest_seen_node(p, curve);
      if (attach == UINT32_MAX) return false;
      // Each node keeps a vertex: where all of a node's vertices would move, the one nearest
      // to it stays.
      std::map<std::uint32_t, std::size_t> leaving;
      for (std::uint32_t k : seeing) ++leaving[node_of_vertex[k]];
      for (const auto& [c, count] : leaving) {
        if (count < sk.nodes[c].vertices.size()) continue;
        std::uint32_t stay = sk.nodes[c].vertices.front();
        for (std::uint32_t k : sk.nodes[c].vertices)
          if (glm::length(original.positions[k] - sk.nodes[c].position) <
              glm::length(original.positions[stay] - sk.nodes[c].position))
            stay = k;
        std::erase(seeing, stay);
      }
      if (seeing.empty()) return false;
      const auto id = static_cast<std::uint32_t>(sk.nodes.size());
      for (const auto& [c, count] : leaving)
        std::erase_if(sk.nodes[c].vertices, [&](std::uint32_t k) {
          return std::binary_search(seeing.begin(), seeing.end(), k);
        });
      for (std::uint32_t k : seeing) node_of_vertex[k] = id;
      Node node;
      node.position = p;
      node.radius = surface.radius(p, seeing);
      node.vertices = std::move(seeing);
      sk.nodes.push_back(std::move(node));
      add_edge(edges, attach, id);
      return true;
    };
    bool any = false;
    for (std::uint32_t root : region_order) {
      const std::vector<std::uint32_t>& region = region_members[root];
      glm::dvec3 mean(0.0);
      double r = 0.0;
      for (std::uint32_t k : region) mean += glm::dvec3(surface.centre[k]), r += vertex_radius[k];
      const double count = static_cast<double>(region.size());
      if (touches(glm::vec3(mean / count), static_cast<float>(r / count), UINT32_MAX)) continue;
      // A limb reaches farther from where it leaves the rest of the surface (its base) than
      // the base's radius; a bump reaches at most a hemisphere, and a band along a flattened
      // body or a plate's rim is as wide along its base as it is far from it.
      // A region that borders a sheet continues the plate that the sheet describes (the C
      // plate's ends), not a limb.
      glm::dvec3 base(0.0);
      std::vector<std::uint32_t> boundary;
      bool borders_sheet = false;
      for (std::uint32_t k : region)
        for (std::uint32_t i = ring_start[k]; i < ring_start[k + 1]; ++i) {
          const std::uint32_t w = ring[i];
          if (outside[w] || stamp[w] == root + 1) continue;
          stamp[w] = root + 1;
          boundary.push_back(w);
          base += glm::dvec3(original.positions[w]);
          borders_sheet = borders_sheet || node_of_vertex[w] == UINT32_MAX || sk.nodes[node_of_vertex[w]].sheet;
        }
      if (boundary.empty() || borders_sheet) continue;
      base /= static_cast<double>(boundary.size());
      double base_radius = 0.0, reach = 0.0;
      for (std::uint32_t w : boundary)
        base_radius = std::max(base_radius, glm::length(glm::dvec3(original.positions[w]) - base));
      for (std::uint32_t k : region) {
        double nearest = std::numeric_limits<double>::infinity();
        for (std::uint32_t w : boundary)
          nearest = std::min(nearest, glm::length(glm::dvec3(original.positions[k]) - glm::dvec3(original.positions[w])));
        reach = std::max(reach, nearest);
      }
      if (!(reach > base_radius)) continue;
      if (add_leaf(region)) {
        any = true;
        continue;
      }
      const Pieces split = split_region(surface, diag, region);
      if (split.mostly_flat) continue;
      std::vector<std::pair<float, std::uint32_t>> order;
      for (std::uint32_t i = 0; i < split.pieces.size(); ++i) {
        float best = std::numeric_limits<float>::max();
        for (const Node& node : sk.nodes)
          if (!node.sheet) best = std::min(best, glm::length(node.position - surface.centre[split.pieces[i].front()]));
        order.push_back({best, i});
      }
      std::sort(order.begin(), order.end());
      for (const auto& [d, i] : order) any |= add_leaf(split.pieces[i]);
    }
    if (!any) break;
  }
  if (options.extend_leaves && sk.nodes.size() > first_new) {
    std::vector<std::vector<std::uint32_t>> adjacency(sk.nodes.size());
    for (const auto& e : edges) adjacency[e[0]].push_back(e[1]), adjacency[e[1]].push_back(e[0]);
    const std::size_t count = sk.nodes.size();
    for (auto leaf = static_cast<std::uint32_t>(first_new); leaf < count; ++leaf) extend_tip(sk, edges, node_of_vertex, surface, leaf, adjacency);
  }
  if (options.section_nodes) {
    std::vector<std::array<std::uint32_t, 2>> added;
    for (const auto& e : edges)
      if (e[1] >= first_new) added.push_back(e);
    add_sections(sk, edges, node_of_vertex, moved, surface, added);
  }
}

void validate(const SkeletonOptions& o) {
  if (!(o.ggt >= 0.0 && o.ggt < 1.0)) throw InputError("skeleton option ggt must be in [0, 1)");
  if (!(o.sheet_spacing >= 0.0 && o.sheet_spacing < 1.0))
    throw InputError("skeleton option sheet_spacing must be in [0, 1)");
  if (!(o.gmt >= 0.0 && o.gmt < 100.0)) throw InputError("skeleton option gmt must be in [0, 100)");
  if (!(o.shape_weight >= 0.0) || !(o.sampling_weight >= 0.0) ||
      o.shape_weight + o.sampling_weight <= 0.0)
    throw InputError("skeleton collapse cost weights must be >= 0 and not both 0");
}

// A contracted proxy of the input (extract() with ContractionOptions::proxy_vertices): the
// surgery runs on it, and its nodes' members are expanded to the input vertices merged into
// each proxy vertex.
struct ContractedProxy {
  const Mesh& contracted;                       // the contracted proxy
  const std::vector<std::uint32_t>& vertex_map;  // per input vertex: its proxy vertex
};

// Per proxy vertex: the input vertices merged into it (vertex_map: per input vertex its proxy
// vertex).
std::vector<std::vector<std::uint32_t>> proxy_inputs(const std::vector<std::uint32_t>& vertex_map,
                                                     std::size_t proxy_vertices) {
  std::vector<std::vector<std::uint32_t>> inputs(proxy_vertices);
  for (std::uint32_t k = 0; k < vertex_map.size(); ++k) inputs[vertex_map[k]].push_back(k);
  return inputs;
}

// The mean of values[k] over `members`, summed as Sum; `none` when there are no members.
template <typename Sum, typename T>
T mean_over(const std::vector<std::uint32_t>& members, const std::vector<T>& values, T none) {
  if (members.empty()) return none;
  Sum sum(0.0);
  for (std::uint32_t k : members) sum += Sum(values[k]);
  return T(sum / static_cast<double>(members.size()));
}

// Connectivity surgery on the contracted input, or on the contracted proxy with per proxy
// vertex the mean local radius and centre point of its input vertices; node members are input
// vertices either way.
detail::CurveGraph surgery(const Surface& surface, const std::vector<float>& local_radius,
                           const ContractedProxy* proxy, const detail::SurgeryOptions& so) {
  if (proxy == nullptr) return detail::collapse_to_curves(surface.contracted, local_radius, surface.centre, so);
  const std::size_t m = proxy->contracted.positions.size();
  const std::vector<std::vector<std::uint32_t>> inputs = proxy_inputs(proxy->vertex_map, m);
  std::vector<float> radius(m);
  std::vector<glm::vec3> centre(m);
  for (std::uint32_t p = 0; p < m; ++p) {
    radius[p] = mean_over<double>(inputs[p], local_radius, 0.0f);
    centre[p] = mean_over<glm::dvec3>(inputs[p], surface.centre, proxy->contracted.positions[p]);
  }
  detail::CurveGraph graph = detail::collapse_to_curves(proxy->contracted, radius, centre, so);
  for (std::vector<std::uint32_t>& members : graph.members) {
    std::vector<std::uint32_t> expanded;
    for (std::uint32_t p : members) expanded.insert(expanded.end(), inputs[p].begin(), inputs[p].end());
    members = std::move(expanded);
  }
  return graph;
}

// `surface`: Surface(original, contracted, sdf), built once for both of build_keeping_handles'
// calls (it depends only on those three).
Skeleton build(const Surface& surface, const SkeletonOptions& options, const ContractedProxy* proxy,
               bool keep_handles) {
  const Mesh& original = surface.original;
  const Mesh& contracted = surface.contracted;
  const std::vector<float>& sdf = surface.sdf;
  const std::size_t n = original.positions.size();

  const double diag = bounding_box(original.positions).diagonal();
  std::vector<float> local_radius(n);
  for (std::size_t k = 0; k < n; ++k)
    local_radius[k] = sdf.empty() ? glm::length(original.positions[k] - contracted.positions[k])
                                  : 0.5f * sdf[k];
  detail::SurgeryOptions so;
  so.shape_weight = options.shape_weight;
  so.sampling_weight = options.sampling_weight;
  so.grouping_global = options.ggt * diag;
  so.grouping_local = options.gmt;
  so.keep_handles = keep_handles;
  Stopwatch watch;
  // Grouping never joins nodes whose segment leaves the solid (a head grouped with the feet).
  so.segment_inside = [&surface](const glm::vec3& a, const glm::vec3& b) {
    return !surface.bvh.segment_blocked(a, b) && surface.bvh.inside(a);
  };
  detail::CurveGraph graph = surgery(surface, local_radius, proxy, so);
  watch.lap("connectivity surgery");

  std::size_t curve_nodes = graph.positions.size();
  std::vector<std::uint32_t> owner(n);
  for (std::uint32_t c = 0; c < curve_nodes; ++c)
    for (std::uint32_t k : graph.members[c]) owner[k] = c;

  std::vector<std::vector<std::uint32_t>> members = graph.members;
  // Each curve node's mesh component (the surgery's nodes hold vertices of one component).
  std::vector<std::uint32_t> curve_component(curve_nodes, UINT32_MAX);
  for (std::uint32_t c = 0; c < curve_nodes; ++c)
    if (!members[c].empty()) curve_component[c] = surface.component[members[c].front()];
  std::vector<glm::vec3> position(curve_nodes);
  for (std::uint32_t c = 0; c < curve_nodes; ++c)
    position[c] = surface.place(graph.positions[c], members[c], options.refine_embedding);

  watch.lap("node placement");
  // A vertex that cannot see its node moves to the closest node it can see among the node's
  // graph neighbours and the kNearestNodes nodes nearest to the vertex.
  std::vector<std::vector<std::uint32_t>> graph_adjacency(curve_nodes);
  for (const auto& e : graph.edges) {
    graph_adjacency[e[0]].push_back(e[1]);
    graph_adjacency[e[1]].push_back(e[0]);
  }
  // Per vertex, independently (node positions are fixed here): the node it ends with, or
  // UINT32_MAX when it sees none (then, with sheets on, its sheet point if it has one).
  std::vector<std::uint32_t> choice(n);
  std::vector<std::uint32_t> leftover_unseen;
  std::vector<std::uint8_t> has_sheet_point(n, 0);
  std::vector<glm::vec3> sheet_point(n);
  parallel_for(n, [&](std::size_t begin, std::size_t end) {
    for (auto k = static_cast<std::uint32_t>(begin); k < end; ++k) {
      choice[k] = owner[k];
      if (surface.sees(k, position[owner[k]])) continue;
      const glm::vec3 u = original.positions[k];
      std::vector<std::pair<float, std::uint32_t>> by_distance;
      for (std::uint32_t c = 0; c < curve_nodes; ++c)
        if (c != owner[k] && curve_component[c] == surface.component[k])
          by_distance.push_back({glm::length(position[c] - u), c});
      const std::size_t nearest = std::min<std::size_t>(kNearestNodes, by_distance.size());
      std::partial_sort(by_distance.begin(), by_distance.begin() + static_cast<std::ptrdiff_t>(nearest),
                        by_distance.end());
      by_distance.resize(nearest);
      for (std::uint32_t c : graph_adjacency[owner[k]])
        by_distance.push_back({glm::length(position[c] - u), c});
      std::sort(by_distance.begin(), by_distance.end());
      choice[k] = UINT32_MAX;
      for (const auto& [d, c] : by_distance)
        if (surface.sees(k, position[c])) {
          choice[k] = c;
          break;
        }
    }
  });
  // Regions of vertices that see no curve node (connected over mesh edges) get a curve node of
  // their own where one stands for them: a part the contraction merged into its neighbour (a
  // finger, an ear, a limb's end) whose vertices see the centre of their region. The node sits
  // at the mean of the region's centre points and is joined to the nearest curve node it sees
  // through the solid. A region is left to the sheets when fewer than half its vertices see
  // that point (a non-convex cross-section: the C and S plates) or no node is seen from it.
  // Up to three rounds: what the first node leaves unseen (a long limb's tip) may get the next.
  std::vector<std::uint8_t> region_is_sheet(n, 0);
  // The local radius of each curve node (SDF/2 over the vertices it stands for), for the union
  // of balls swept along the curve edges that the skeleton stands for.
  std::vector<float> node_radius(curve_nodes);
  for (std::uint32_t c = 0; c < curve_nodes; ++c)
    node_radius[c] = graph.members[c].empty() ? 0.0f : surface.radius(position[c], graph.members[c]);
  // A new curve node at the mean of `part`'s centre points for the vertices of `part` that
  // see it, joined to the nearest curve node it sees, or put on the curve edge whose swept ball
  // it lies in (below); false when under half of them see it or no node is seen from it.
  auto add_node = [&](const std::vector<std::uint32_t>& part) {
    const std::optional<Surface::RegionNode> node = surface.region_node(part);
    if (!node) return false;
    const glm::vec3 p = node->point;
    const std::vector<std::uint32_t>& seeing = node->seeing;
    const std::uint32_t comp = surface.component[part.front()];  // a region is connected
    // A region whose centre points all lie in the union the curve already stands for is a
    // part of a limb that the curve passes through (vertices in a crease of the limb that see
    // none of its nodes), not a part the skeleton misses: its node goes on the curve edge whose
    // swept ball holds it, which keeps the leaves the skeleton has, instead of hanging off the
    // curve as a spur. A region with centre points outside (an ear whose base lies in the
    // body's balls) is a part the skeleton misses and gets its branch.
    const auto in_union = [&](const glm::vec3& q) {
      for (const auto& [a, b] : graph.edges)
        if (curve_component[a] == comp &&
            outside_swept_ball(q, position[a], node_radius[a], position[b], node_radius[b]) <= 0.0f)
          return true;
      return false;
    };
    bool covered = true;
    for (std::uint32_t k : part)
      if (!in_union(surface.centre[k])) {
        covered = false;
        break;
      }
    std::size_t split = graph.edges.size();
    float split_distance = std::numeric_limits<float>::max();
    for (std::size_t i = 0; i < graph.edges.size() && covered; ++i) {
      const auto [a, b] = graph.edges[i];
      if (curve_component[a] != comp ||
          outside_swept_ball(p, position[a], node_radius[a], position[b], node_radius[b]) > 0.0f)
        continue;
      const float d = distance_to_segment(p, position[a], position[b]);
      if (d < split_distance && !surface.bvh.segment_blocked(position[a], p) && !surface.bvh.segment_blocked(p, position[b]))
        split = i, split_distance = d;
    }
    std::uint32_t attach = UINT32_MAX;
    if (split == graph.edges.size()) {
      std::vector<std::pair<std::uint32_t, glm::vec3>> curve;
      for (std::uint32_t c = 0; c < curve_nodes; ++c)
        if (curve_component[c] == comp) curve.push_back({c, position[c]});
      attach = surface.nearest_seen_node(p, curve);
      if (attach == UINT32_MAX) return false;
    }
    const auto c = static_cast<std::uint32_t>(curve_nodes++);
    position.push_back(p);
    curve_component.push_back(comp);
    node_radius.push_back(surface.radius(p, seeing));
    members.emplace_back();
    graph.members.emplace_back();
    graph.positions.push_back(p);
    graph_adjacency.emplace_back();
    auto link = [&](std::uint32_t a, std::uint32_t b) {
      graph.edges.push_back({std::min(a, b), std::max(a, b)});
      graph_adjacency[a].push_back(b);
      graph_adjacency[b].push_back(a);
    };
    if (split < graph.edges.size()) {
      const auto [a, b] = graph.edges[split];
      graph.edges.erase(graph.edges.begin() + static_cast<std::ptrdiff_t>(split));
      std::erase(graph_adjacency[a], b);
      std::erase(graph_adjacency[b], a);
      link(a, c);
      link(c, b);
    } else {
      link(attach, c);
    }
    for (std::uint32_t k : seeing) choice[k] = c;
    return true;
  };
  // A node for each piece (add_node), the pieces nearest to the existing skeleton first, so a
  // missed limb becomes a chain of nodes; true when any was added.
  auto add_piece_nodes = [&](const Pieces& split) {
    std::vector<std::pair<float, std::uint32_t>> order;
    for (std::uint32_t i = 0; i < split.pieces.size(); ++i) {
      float best = std::numeric_limits<float>::max();
      const std::uint32_t first = split.pieces[i].front();
      for (std::uint32_t c = 0; c < curve_nodes; ++c)
        if (curve_component[c] == surface.component[first])
          best = std::min(best, glm::length(position[c] - surface.centre[first]));
      order.push_back({best, i});
    }
    std::sort(order.begin(), order.end());
    bool added = false;
    for (const auto& [d, i] : order) added |= add_node(split.pieces[i]);
    return added;
  };
  for (int round = 0; round < 3; ++round) {
    UnionFind regions(n);
    bool any = false;
    for (const Triangle& t : original.triangles)
      for (int i = 0; i < 3; ++i) {
        const std::uint32_t a = t[i], b = t[(i + 1) % 3];
        if (choice[a] == UINT32_MAX && choice[b] == UINT32_MAX && !region_is_sheet[a]) regions.unite(a, b);
      }
    std::map<std::uint32_t, std::vector<std::uint32_t>> region_members;  // root -> vertices (ascending)
    std::vector<std::uint32_t> region_order;
    for (std::uint32_t k = 0; k < n; ++k)
      if (choice[k] == UINT32_MAX && !region_is_sheet[k]) {
        auto [it, inserted] = region_members.try_emplace(regions.find(k));
        if (inserted) region_order.push_back(regions.find(k));
        it->second.push_back(k);
      }
    for (std::uint32_t root : region_order) {
      const std::vector<std::uint32_t>& region = region_members[root];
      if (add_node(region)) {
        any = true;
        continue;
      }
      // The region is too large or bent for one node. Split it into pieces of connected
      // vertices whose centre points share a cell of kRegionCell * diag, and look at the shape
      // of each piece's centre points: along a tube they lie on a line (the second principal
      // spread is small), across a plate with a non-convex cross-section they fill the cell.
      // A region whose pieces are mostly flat is a sheet; otherwise each piece gets a node,
      // nearest to the existing skeleton first, so a missed limb becomes a chain of nodes.
      const Pieces split = split_region(surface, diag, region);
      if (split.mostly_flat && static_cast<double>(region.size()) >= kSheetRegionShare * static_cast<double>(n)) {
        for (std::uint32_t k : region) region_is_sheet[k] = 1;
        continue;
      }
      any |= add_piece_nodes(split);
    }
    if (!any) break;
  }
  // Vertices still without a node outside sheet regions (a few around a new node) stay with
  // the node the surgery gave them: unreliable, but no sheet blob at a limb's end.
  for (std::uint32_t k = 0; k < n; ++k)
    if (choice[k] == UINT32_MAX && !region_is_sheet[k]) {
      choice[k] = owner[k];
      leftover_unseen.push_back(k);
    }
  // Apply in vertex order: a vertex moves to its chosen node; one that sees none stays
  // (failing) or, with sheets, leaves its curve node and becomes a sheet vertex (below).
  if (options.sheets)
    parallel_for(n, [&](std::size_t begin, std::size_t end) {
      for (auto k = static_cast<std::uint32_t>(begin); k < end; ++k)
        if (choice[k] == UINT32_MAX)
          if (const auto p = surface.sheet_point(k)) has_sheet_point[k] = 1, sheet_point[k] = *p;
    });
  std::vector<std::uint8_t> in_sheet(n, 0);
  std::size_t failing = leftover_unseen.size();
  std::vector<std::vector<std::uint32_t>> moved_in(curve_nodes);
  for (std::uint32_t k = 0; k < n; ++k) {
    if (choice[k] == owner[k]) continue;
    if (choice[k] != UINT32_MAX) {
      moved_in[choice[k]].push_back(k);
      owner[k] = choice[k];
    } else {
      ++failing;
      in_sheet[k] = has_sheet_point[k];
    }
  }
  for (std::uint32_t c = 0; c < curve_nodes; ++c) {
    std::erase_if(members[c], [&](std::uint32_t k) { return owner[k] != c || in_sheet[k]; });
    members[c].insert(members[c].end(), moved_in[c].begin(), moved_in[c].end());
  }
  Skeleton sk;
  sk.curve_reliability = 1.0 - static_cast<double>(failing) / static_cast<double>(n);
  watch.lap("visibility");

  // A curve node whose vertices all moved to nodes they see is merged below into its nearest
  // graph neighbour; where that neighbour and the node share another neighbour, the merge would
  // close a triangle of the graph to a double edge and so remove a cycle (a handle of a coarse
  // mesh whose three nodes are its whole ring: 3torus, P). Such a node keeps one vertex: of the
  // vertices the surgery gave it, the one nearest to it that sees it (else the nearest), taken
  // from a node that keeps at least one.
  for (std::uint32_t c = 0; c < curve_nodes; ++c) {
    if (!members[c].empty() || graph_adjacency[c].size() < 2) continue;
    std::uint32_t nearest = graph_adjacency[c].front();
    for (std::uint32_t d : graph_adjacency[c])
      if (glm::length(position[d] - position[c]) < glm::length(position[nearest] - position[c])) nearest = d;
    bool closes = false;
    for (std::uint32_t d : graph_adjacency[c])
      if (d != nearest && std::find(graph_adjacency[nearest].begin(), graph_adjacency[nearest].end(), d) !=
                              graph_adjacency[nearest].end())
        closes = true;
    if (!closes) continue;
    std::uint32_t best = UINT32_MAX;
    float best_d = std::numeric_limits<float>::max();
    bool best_sees = false;
    for (std::uint32_t k : graph.members[c]) {
      if (in_sheet[k] || owner[k] == c || members[owner[k]].size() < 2) continue;
      const bool sees = surface.sees(k, position[c]);
      const float d = glm::length(original.positions[k] - position[c]);
      if ((sees && !best_sees) || (sees == best_sees && d < best_d)) best = k, best_d = d, best_sees = sees;
    }
    if (best == UINT32_MAX) continue;
    std::erase(members[owner[best]], best);
    owner[best] = c;
    members[c].push_back(best);
  }
  // Curve nodes that still represent vertices, in order, then one sheet node per sheet vertex.
  std::vector<std::uint32_t> node_of_curve(curve_nodes, UINT32_MAX);
  for (std::uint32_t c = 0; c < curve_nodes; ++c) {
    if (members[c].empty()) continue;
    node_of_curve[c] = static_cast<std::uint32_t>(sk.nodes.size());
    Node node;
    node.position = position[c];
    node.vertices = members[c];
    node.radius = surface.radius(node.position, node.vertices);
    sk.nodes.push_back(std::move(node));
  }
  // A curve node left without vertices merges into its nearest graph neighbour (chains of
  // such nodes follow), so dropping it does not cut the curve; each merged group holds at
  // most one node with vertices, because every empty node makes exactly one merge.
  {
    std::vector<std::uint32_t> group(curve_nodes);
    std::iota(group.begin(), group.end(), 0u);
    auto find = [&](std::uint32_t x) {
      while (group[x] != x) x = group[x] = group[group[x]];
      return x;
    };
    for (std::uint32_t c = 0; c < curve_nodes; ++c) {
      if (!members[c].empty() || graph_adjacency[c].empty()) continue;
      std::uint32_t nearest = graph_adjacency[c].front();
      for (std::uint32_t d : graph_adjacency[c])
        if (glm::length(position[d] - position[c]) < glm::length(position[nearest] - position[c]))
          nearest = d;
      group[find(c)] = find(nearest);
    }
    std::vector<std::uint32_t> kept(curve_nodes, UINT32_MAX);
    for (std::uint32_t c = 0; c < curve_nodes; ++c)
      if (!members[c].empty()) kept[find(c)] = node_of_curve[c];
    for (std::uint32_t c = 0; c < curve_nodes; ++c)
      if (members[c].empty()) node_of_curve[c] = kept[find(c)];
  }
  std::vector<std::uint32_t> node_of_vertex(n, UINT32_MAX);
  for (std::uint32_t k = 0; k < n; ++k)
    if (!in_sheet[k]) node_of_vertex[k] = node_of_curve[owner[k]];
  add_sheet_nodes(surface, in_sheet, sheet_point, options.sheet_spacing * diag, sk.nodes, node_of_vertex);
  watch.lap("sheet nodes");

  EdgeSet edges;
  for (const auto& e : graph.edges) add_edge(edges, node_of_curve[e[0]], node_of_curve[e[1]]);
  std::set<Triangle> sheet_seen;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> links;  // (curve node, sheet node)
  for (const Triangle& t : original.triangles) {
    const bool s0 = in_sheet[t[0]], s1 = in_sheet[t[1]], s2 = in_sheet[t[2]];
    if (s0 && s1 && s2) {
      const Triangle st = {node_of_vertex[t[0]], node_of_vertex[t[1]], node_of_vertex[t[2]]};
      if (st[0] != st[1] && st[1] != st[2] && st[0] != st[2]) {
        Triangle key = st;
        std::sort(key.begin(), key.end());
        if (sheet_seen.insert(key).second) sk.sheet_triangles.push_back(st);
      } else {
        // A triangle that clusters to an edge keeps that edge.
        for (int i = 0; i < 3; ++i) add_edge(edges, st[i], st[(i + 1) % 3]);
      }
      continue;
    }
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t a = t[i], b = t[(i + 1) % 3];
      if (in_sheet[a] && in_sheet[b])
        add_edge(edges, node_of_vertex[a], node_of_vertex[b]);  // keeps the sheet connected
      else if (in_sheet[a] != in_sheet[b])
        links.push_back({node_of_vertex[in_sheet[a] ? b : a], node_of_vertex[in_sheet[a] ? a : b]});
    }
  }
  // Where the sheet meets a curve: each curve node is linked to the nearest sheet node it
  // touches (through a mesh edge) in each connected piece of sheet, so a curve meets a sheet in
  // one edge instead of a fan of edges that would close spurious cycles.
  {
    std::vector<std::uint32_t> piece(sk.nodes.size());
    std::iota(piece.begin(), piece.end(), 0u);
    auto find = [&](std::uint32_t x) {
      while (piece[x] != x) x = piece[x] = piece[piece[x]];
      return x;
    };
    for (const auto& e : edges) piece[find(e[0])] = find(e[1]);
    for (const Triangle& t : sk.sheet_triangles) piece[find(t[0])] = find(t[1]), piece[find(t[1])] = find(t[2]);
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::pair<float, std::uint32_t>> best;
    for (const auto& [curve, sheet] : links) {
      if (curve == UINT32_MAX || sheet == UINT32_MAX) continue;
      const float d = glm::length(sk.nodes[curve].position - sk.nodes[sheet].position);
      auto [it, inserted] = best.try_emplace({curve, find(sheet)}, d, sheet);
      if (!inserted && d < it->second.first) it->second = {d, sheet};
    }
    for (const auto& [key, value] : best) add_edge(edges, key.first, value.second);
  }
  const EdgeSet through_air = route_edges_inside(sk, edges, node_of_vertex, surface);
  prune_cycles(sk, edges, through_air, original);
  if (options.prune_branches) prune_covered_branches(sk, edges, node_of_vertex);
  // Leaves reach the end of their limb: a curve leaf's node sits at the centre of its vertices'
  // region, short of the limb's tip. Its vertex farthest along the direction from its neighbour
  // gives the tip (that vertex's centre point); when the tip lies over a node radius beyond the
  // leaf and the segment to it is inside, a tip node takes the leaf's vertices that lie beyond
  // the midpoint and see it (the leaf keeps at least one), placed at their centre.
  //
  // First, a leaf that lies along the edge its neighbour continues on is a point of that limb,
  // not its end (s11leaves): the surgery can join a hip straight to the foot and leave the
  // knee's node hanging off the foot. Where a curve leaf L hangs from a degree-2 curve node F
  // whose other neighbour is H, L projects strictly between H and F, lies within the tube of
  // HF (the ends' radii interpolated) or HF passes through L's own ball (a bent knee lies off
  // the hip-foot chord by more than the thinner foot's radius gives, but within its own: homer's
  // right knee, 0.064 from the chord, tube 0.062, its radius 0.068), and the segment HL is
  // inside, the curve runs H-L-F and F, the farther node, becomes the leaf. Leaf count,
  // junctions and cycles are unchanged.
  if (options.extend_leaves) {
    std::vector<std::vector<std::uint32_t>> adjacency(sk.nodes.size());
    for (const auto& e : edges) adjacency[e[0]].push_back(e[1]), adjacency[e[1]].push_back(e[0]);
    for (std::uint32_t leaf = 0; leaf < sk.nodes.size(); ++leaf) {
      if (adjacency[leaf].size() != 1 || sk.nodes[leaf].sheet) continue;
      const std::uint32_t f = adjacency[leaf].front();
      if (adjacency[f].size() != 2 || sk.nodes[f].sheet) continue;
      const std::uint32_t h = adjacency[f][0] == leaf ? adjacency[f][1] : adjacency[f][0];
      if (sk.nodes[h].sheet) continue;
      const glm::vec3 a = sk.nodes[h].position, b = sk.nodes[f].position, p = sk.nodes[leaf].position;
      const float len2 = glm::dot(b - a, b - a);
      if (!(len2 > 0.0f)) continue;
      const float t = glm::dot(p - a, b - a) / len2;
      if (!(t > 0.0f && t < 1.0f)) continue;
      const float tube = (1.0f - t) * sk.nodes[h].radius + t * sk.nodes[f].radius;
      const float reach = std::max(tube, sk.nodes[leaf].radius);
      if (glm::length(p - (a + t * (b - a))) >= reach || surface.bvh.segment_blocked(a, p)) continue;
      edges.erase({std::min(h, f), std::max(h, f)});
      add_edge(edges, h, leaf);
      adjacency[f] = {leaf};
      adjacency[leaf] = {f, h};
      std::replace(adjacency[h].begin(), adjacency[h].end(), f, leaf);
    }
    const std::size_t count = sk.nodes.size();
    for (std::uint32_t leaf = 0; leaf < count; ++leaf) extend_tip(sk, edges, node_of_vertex, surface, leaf, adjacency);
  }
  // Cross-section nodes along the curve edges (add_sections); `moved` marks the vertices that
  // moved to a section, each at most once, here and for the protrusions' edges below.
  std::vector<std::uint8_t> moved(n, 0);
  if (options.section_nodes)
    add_sections(sk, edges, node_of_vertex, moved, surface, std::vector<std::array<std::uint32_t, 2>>(edges.begin(), edges.end()));
  if (options.unfold_branches) unfold_branches(sk, edges, surface);
  if (options.protrusion_branches) add_protrusion_branches(sk, edges, node_of_vertex, moved, surface, options);
  // Sheet-triangle edges are part of the sheet, not curve edges.
  std::set<std::array<std::uint32_t, 2>> sheet_edges;
  for (const Triangle& t : sk.sheet_triangles)
    for (int i = 0; i < 3; ++i)
      sheet_edges.insert({std::min(t[i], t[(i + 1) % 3]), std::max(t[i], t[(i + 1) % 3])});
  for (const auto& e : edges)
    if (!sheet_edges.count(e)) sk.edges.push_back(e);

  std::vector<std::uint8_t> sees_node(n, 0);
  parallel_for(n, [&](std::size_t begin, std::size_t end) {
    for (auto k = static_cast<std::uint32_t>(begin); k < end; ++k)
      sees_node[k] = surface.sees(k, sk.nodes[node_of_vertex[k]].position);
  });
  const auto seen = static_cast<std::size_t>(std::count(sees_node.begin(), sees_node.end(), 1));
  sk.reliability = static_cast<double>(seen) / static_cast<double>(n);
  watch.lap("edges, sheets and reliability");
  if (sk.reliability < 1.0)
    sk.warnings.push_back(std::to_string(n - seen) + " of " + std::to_string(n) +
                          " surface vertices cannot see their skeleton node" +
                          (options.sheets ? "" : " (sheets are off)"));
  return sk;
}

}  // namespace

namespace {
// Sum over the mesh's connected components of their genus, (2 - chi) / 2.
int total_genus(const Mesh& mesh) {
  UnionFind uf(mesh.positions.size());
  int genus = 0;
  for (const auto& [root, g] : detail::component_genus(mesh, uf)) genus += g;
  return genus;
}

// build() with the surgery's handle guard only where it is needed: the plain surgery (which
// closes a loop whenever a collapse makes its hollow triangle degenerate) is kept when the
// skeleton has as many independent cycles as the mesh's genus; otherwise a handle was closed
// (a thin handle's ring contracted to a few nodes) and the surgery is rerun refusing the
// collapses that close a loop round a hole of the solid, and the skeleton whose cycle count is
// nearer the genus is kept (the plain one on a tie). Deterministic: both runs are.
Skeleton build_keeping_handles(const Mesh& original, const Mesh& contracted, const std::vector<float>& sdf,
                               const SkeletonOptions& options, const ContractedProxy* proxy) {
  Stopwatch watch;
  const Surface surface(original, contracted, sdf);
  watch.lap("BVH and centre points");
  Skeleton plain = build(surface, options, proxy, false);
  const int genus = total_genus(original);
  const int plain_cycles = cycle_count(plain);
  if (plain_cycles >= genus) return plain;
  Skeleton guarded = build(surface, options, proxy, true);
  const int guarded_cycles = cycle_count(guarded);
  log_debug("skeleton: " + std::to_string(plain_cycles) + " cycles for genus " + std::to_string(genus) +
            "; with the surgery's handle guard " + std::to_string(guarded_cycles));
  return std::abs(guarded_cycles - genus) < std::abs(plain_cycles - genus) ? guarded : plain;
}
}  // namespace

Skeleton build_skeleton(const Mesh& original, const Mesh& contracted, const std::vector<float>& sdf,
                        const SkeletonOptions& options) {
  validate(options);
  detail::require_closed(original, "skeleton extraction");
  const std::size_t n = original.positions.size();
  if (contracted.positions.size() != n || contracted.triangles != original.triangles)
    throw InputError("the contracted mesh does not match the original's connectivity");
  if (!sdf.empty() && sdf.size() != n)
    throw InputError("the SDF has " + std::to_string(sdf.size()) + " values for " +
                     std::to_string(n) + " vertices");
  return build_keeping_handles(original, contracted, sdf, options, nullptr);
}

namespace {
double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}
}  // namespace

namespace {
// extract() on a closed edge-manifold mesh.
Skeleton extract_manifold(const Mesh& mesh, SdfBackend* backend, const ContractionOptions& contraction,
                          const SkeletonOptions& options) {
  using Clock = std::chrono::steady_clock;
  Skeleton::Timings seconds;
  SdfOptions so = contraction.sdf;
  so.domain = SdfDomain::Vertex;
  const std::size_t limit = contraction.proxy_vertices;
  const bool use_proxy = limit > 0 && mesh.positions.size() > limit;

  // The proxy path: contract a simplified copy, carry every input vertex along with the proxy
  // vertex it was merged into, and build the skeleton for the input.
  auto t = Clock::now();
  detail::Simplified proxy;
  if (use_proxy) {
    proxy = detail::simplify(mesh, limit);
    seconds.simplify = seconds_since(t);
    log_debug("skeleton: proxy of " + std::to_string(proxy.mesh.positions.size()) + " vertices (" +
              std::to_string(proxy.collapses) + " collapses, " + std::to_string(proxy.refused) +
              " refused) in " + std::to_string(1e3 * seconds.simplify) + " ms");
  }
  // The input's own SDF at full quality (radii, centre points, grouping, Skeleton::sdf): the
  // contraction's first SDF when it contracts the input with the SDF term, else measured here
  // first. With a proxy, each proxy vertex then starts the contraction from the mean over the
  // input vertices merged into it (the proxy stands for the input's surface; one SDF at full
  // quality instead of two).
  const bool contraction_measures_input = !use_proxy && contraction.sdf_term;
  std::vector<float> sdf, proxy_first_sdf;
  if (backend != nullptr && !contraction_measures_input) {
    t = Clock::now();
    backend->set_mesh(mesh);
    sdf = compute_sdf(*backend, mesh, so).values;
    seconds.input_sdf = seconds_since(t);
    if (use_proxy && contraction.sdf_term) {
      const auto inputs = proxy_inputs(proxy.vertex_map, proxy.mesh.positions.size());
      proxy_first_sdf.resize(inputs.size());
      for (std::size_t p = 0; p < inputs.size(); ++p) proxy_first_sdf[p] = mean_over<float>(inputs[p], sdf, 0.0f);
    }
  }
  t = Clock::now();
  // A mesh with a handle (a component of genus > 0: V - E + F < 2 per component) is contracted
  // with ContractionOptions::sl_handles.
  ContractionOptions used = contraction;
  {
    std::vector<std::uint64_t> mesh_edges;
    mesh_edges.reserve(3 * mesh.triangles.size());
    for (const Triangle& tri : mesh.triangles)
      for (int i = 0; i < 3; ++i)
        mesh_edges.push_back(std::uint64_t{std::min(tri[i], tri[(i + 1) % 3])} << 32 | std::max(tri[i], tri[(i + 1) % 3]));
    std::sort(mesh_edges.begin(), mesh_edges.end());
    mesh_edges.erase(std::unique(mesh_edges.begin(), mesh_edges.end()), mesh_edges.end());
    const auto chi = static_cast<long long>(mesh.positions.size()) - static_cast<long long>(mesh_edges.size()) +
                     static_cast<long long>(mesh.triangles.size());
    if (chi < 2 * static_cast<long long>(analyze(mesh).components)) used.sl = contraction.sl_handles;
  }
  ContractionResult c = contract(use_proxy ? proxy.mesh : mesh, backend, used, proxy_first_sdf);
  seconds.contraction = seconds_since(t);
  seconds.contraction_sdf = c.sdf_seconds;
  seconds.contraction_solve = c.solve_seconds;
  if (contraction_measures_input) sdf = std::move(c.first_sdf);

  t = Clock::now();
  Skeleton sk;
  if (use_proxy) {
    Mesh contracted{.positions = std::vector<glm::vec3>(mesh.positions.size()), .triangles = mesh.triangles};
    for (std::size_t k = 0; k < mesh.positions.size(); ++k)
      contracted.positions[k] = c.contracted.positions[proxy.vertex_map[k]];
    const ContractedProxy contracted_proxy{c.contracted, proxy.vertex_map};
    sk = build_keeping_handles(mesh, contracted, sdf, options, &contracted_proxy);
  } else {
    sk = build_keeping_handles(mesh, c.contracted, sdf, options, nullptr);
  }
  seconds.build = seconds_since(t);
  sk.iterations = c.iterations;
  sk.contracted_vertices = use_proxy ? proxy.mesh.positions.size() : mesh.positions.size();
  sk.sdf = std::move(sdf);
  sk.seconds = seconds;
  sk.warnings.insert(sk.warnings.begin(), c.warnings.begin(), c.warnings.end());
  return sk;
}

}  // namespace

Skeleton extract(const Mesh& mesh, SdfBackend* backend, const ContractionOptions& contraction,
                 const SkeletonOptions& options) {
  validate(options);
  // Vertices no triangle uses are left out: the skeleton is the surface's, and such a vertex would
  // stay where it is through the contraction (no Laplacian row), become a node of its own outside
  // the solid, and stretch the bounding box the skeleton's scales come from.
  const std::size_t n_in = mesh.positions.size();
  std::vector<std::uint32_t> used(n_in, 0);
  bool in_range = true;  // else the checks below report the bad index
  for (const Triangle& t : mesh.triangles)
    for (std::uint32_t v : t)
      if (v < n_in) used[v] = 1;
      else in_range = false;
  const auto n_used = static_cast<std::size_t>(std::count(used.begin(), used.end(), 1u));
  if (in_range && n_used < n_in && n_used > 0) {
    Mesh surface;
    std::vector<std::uint32_t> kept;  // surface vertex -> input vertex
    kept.reserve(n_used);
    for (std::uint32_t v = 0; v < n_in; ++v)
      if (used[v]) used[v] = static_cast<std::uint32_t>(kept.size()) + 1, kept.push_back(v);  // 1-based index
    surface.positions.reserve(n_used);
    for (std::uint32_t v : kept) surface.positions.push_back(mesh.positions[v]);
    surface.triangles.reserve(mesh.triangles.size());
    for (const Triangle& t : mesh.triangles) surface.triangles.push_back({used[t[0]] - 1, used[t[1]] - 1, used[t[2]] - 1});
    Skeleton sk = extract(surface, backend, contraction, options);
    for (Node& node : sk.nodes)
      for (std::uint32_t& v : node.vertices) v = kept[v];
    if (!sk.sdf.empty()) {
      std::vector<float> sdf(n_in, 0.0f);
      for (std::size_t k = 0; k < kept.size(); ++k) sdf[kept[k]] = sk.sdf[k];
      sk.sdf = std::move(sdf);
    }
    const std::size_t left = n_in - n_used;
    sk.warnings.insert(sk.warnings.begin(), std::to_string(left) +
                                                (left == 1 ? " vertex no triangle uses is" : " vertices no triangle uses are") +
                                                " left out of the skeleton");
    return sk;
  }
  // A closed mesh with non-manifold edges (parts touching along an edge) is split there into
  // closed edge-manifold surfaces; the skeleton is built for that mesh and its vertex indices
  // are mapped back to the input's (the copies come after the input's vertices).
  const detail::ManifoldSplit split = detail::split_non_manifold(mesh, "skeleton extraction");
  if (!split.applied) return extract_manifold(mesh, backend, contraction, options);
  Skeleton sk = extract_manifold(split.mesh, backend, contraction, options);
  const std::size_t n = mesh.positions.size();
  std::vector<std::uint8_t> assigned(n, 0);
  for (Node& node : sk.nodes) {
    std::vector<std::uint32_t> kept;
    for (std::uint32_t k : node.vertices) {
      const std::uint32_t v = split.original[k];
      if (!assigned[v]) assigned[v] = 1, kept.push_back(v);
    }
    node.vertices = std::move(kept);
  }
  if (sk.sdf.size() > n) sk.sdf.resize(n);  // a copy's SDF is its original's (same vertex)
  sk.warnings.insert(sk.warnings.begin(),
                     "split " + std::to_string(split.non_manifold_edges) +
                         " non-manifold edges (triangles paired across the solid they bound): " +
                         std::to_string(split.mesh.positions.size() - n) + " vertices duplicated");
  return sk;
}

}  // namespace sdfkit::skeleton

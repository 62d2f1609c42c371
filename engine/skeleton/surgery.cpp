#include "surgery.hpp"

#include <Eigen/Core>
#include <glm/geometric.hpp>

#include <algorithm>
#include <queue>

namespace sdfkit::skeleton::detail {
namespace {

bool contains(const std::vector<std::uint32_t>& v, std::uint32_t x) {
  return std::find(v.begin(), v.end(), x) != v.end();
}
void erase_value(std::vector<std::uint32_t>& v, std::uint32_t x) {
  v.erase(std::remove(v.begin(), v.end(), x), v.end());
}

// K^T K for the edge from p toward q: p'^T (K^T K) p' is the squared distance from p' to the
// line through p and q (Au et al. 2008, eq. 4). Zero for a zero-length edge.
Eigen::Matrix4d edge_quadric(const glm::dvec3& p, const glm::dvec3& q) {
  const glm::dvec3 d = q - p;
  const double len = glm::length(d);
  if (!(len > 0.0)) return Eigen::Matrix4d::Zero();
  const glm::dvec3 a = d / len;
  const glm::dvec3 b = glm::cross(a, p);
  Eigen::Matrix<double, 3, 4> K;
  K << 0.0, -a.z, a.y, -b.x,  //
      a.z, 0.0, -a.x, -b.y,   //
      -a.y, a.x, 0.0, -b.z;
  return K.transpose() * K;
}

// The simplicial complex being collapsed: vertices (nodes) with their edges and triangles.
class Complex {
public:
  Complex(const Mesh& mesh, std::span<const float> radius, std::span<const glm::vec3> centres) {
    const std::size_t n = mesh.positions.size();
    p_.resize(n);
    for (std::size_t i = 0; i < n; ++i) p_[i] = glm::dvec3(mesh.positions[i]);
    nbr_.resize(n);
    vf_.resize(n);
    members_.resize(n);
    radius_sum_.assign(n, 0.0);
    centre_sum_.assign(n, glm::dvec3(0.0));
    alive_.assign(n, 1);
    stamp_.assign(n, 0);
    for (std::uint32_t i = 0; i < n; ++i) {
      members_[i] = {i};
      if (i < radius.size()) radius_sum_[i] = radius[i];
      centre_sum_[i] = glm::dvec3(i < centres.size() ? centres[i] : mesh.positions[i]);
    }
    faces_ = mesh.triangles;
    face_alive_.assign(faces_.size(), 1);
    alive_faces_ = faces_.size();
    for (std::uint32_t f = 0; f < faces_.size(); ++f) {
      const Triangle& t = faces_[f];
      for (int k = 0; k < 3; ++k) {
        vf_[t[k]].push_back(f);
        const std::uint32_t a = t[k], b = t[(k + 1) % 3];
        if (!contains(nbr_[a], b)) {
          nbr_[a].push_back(b);
          nbr_[b].push_back(a);
        }
      }
    }
    Q_.assign(n, Eigen::Matrix4d::Zero());
    for (std::uint32_t i = 0; i < n; ++i)
      for (std::uint32_t j : nbr_[i]) Q_[i] += edge_quadric(p_[i], p_[j]);
  }

  std::size_t size() const { return p_.size(); }
  std::size_t alive_faces() const { return alive_faces_; }
  bool alive(std::uint32_t i) const { return alive_[i] != 0; }
  const std::vector<std::uint32_t>& neighbours(std::uint32_t i) const { return nbr_[i]; }
  const glm::dvec3& position(std::uint32_t i) const { return p_[i]; }
  const std::vector<std::uint32_t>& members(std::uint32_t i) const { return members_[i]; }
  double radius(std::uint32_t i) const {
    return radius_sum_[i] / static_cast<double>(members_[i].size());
  }
  glm::dvec3 embedded(std::uint32_t i) const {
    return centre_sum_[i] / static_cast<double>(members_[i].size());
  }
  std::uint32_t stamp(std::uint32_t i) const { return stamp_[i]; }
  void bump(std::uint32_t i) { ++stamp_[i]; }

  bool edge_on_face(std::uint32_t i, std::uint32_t j) const {
    for (std::uint32_t f : vf_[i])
      if (face_alive_[f] && (faces_[f][0] == j || faces_[f][1] == j || faces_[f][2] == j))
        return true;
    return false;
  }
  bool share_neighbour(std::uint32_t i, std::uint32_t j) const {
    for (std::uint32_t k : nbr_[i])
      if (k != j && contains(nbr_[j], k)) return true;
    return false;
  }

  double cost(std::uint32_t i, std::uint32_t j, double wa, double wb) const {
    const Eigen::Vector4d pj(p_[j].x, p_[j].y, p_[j].z, 1.0);
    const double shape = pj.dot((Q_[i] + Q_[j]) * pj);
    double around = 0.0;
    for (std::uint32_t k : nbr_[i]) around += glm::length(p_[i] - p_[k]);
    return wa * shape + wb * glm::length(p_[i] - p_[j]) * around;
  }

  // Half-edge collapse i -> j: i disappears, its triangles and edges move to j.
  void collapse(std::uint32_t i, std::uint32_t j) {
    for (std::uint32_t f : vf_[i]) {
      if (!face_alive_[f]) continue;
      Triangle& t = faces_[f];
      if (t[0] == j || t[1] == j || t[2] == j) {
        kill_face(f);
        continue;
      }
      for (std::uint32_t& v : t)
        if (v == i) v = j;
      bool duplicate = false;
      for (std::uint32_t g : vf_[j])
        if (face_alive_[g] && same_set(faces_[g], t)) duplicate = true;
      if (duplicate)
        kill_face(f);
      else
        vf_[j].push_back(f);
    }
    vf_[i].clear();
    std::erase_if(vf_[j], [&](std::uint32_t f) { return !face_alive_[f]; });

    erase_value(nbr_[j], i);
    for (std::uint32_t k : nbr_[i]) {
      if (k == j) continue;
      erase_value(nbr_[k], i);
      if (!contains(nbr_[k], j)) {
        nbr_[k].push_back(j);
        nbr_[j].push_back(k);
      }
    }
    nbr_[i].clear();
    Q_[j] += Q_[i];
    members_[j].insert(members_[j].end(), members_[i].begin(), members_[i].end());
    members_[i].clear();
    radius_sum_[j] += radius_sum_[i];
    centre_sum_[j] += centre_sum_[i];
    alive_[i] = 0;
  }

private:
  static bool same_set(Triangle a, Triangle b) {
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    return a == b;
  }
  void kill_face(std::uint32_t f) {
    face_alive_[f] = 0;
    --alive_faces_;
  }

  std::vector<glm::dvec3> p_;
  std::vector<std::vector<std::uint32_t>> nbr_, vf_, members_;
  std::vector<double> radius_sum_;
  std::vector<glm::dvec3> centre_sum_;
  std::vector<std::uint8_t> alive_;
  std::vector<std::uint32_t> stamp_;
  std::vector<Triangle> faces_;
  std::vector<std::uint8_t> face_alive_;
  std::size_t alive_faces_ = 0;
  std::vector<Eigen::Matrix4d> Q_;
};

struct Candidate {
  double cost;
  std::uint32_t from, to, stamp;
  bool operator>(const Candidate& o) const {
    return cost != o.cost ? cost > o.cost : (from != o.from ? from > o.from : to > o.to);
  }
};

void remove_all_faces(Complex& c, const SurgeryOptions& o, std::size_t& collapses) {
  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<>> queue;
  auto push_out = [&](std::uint32_t i) {
    for (std::uint32_t j : c.neighbours(i))
      if (c.edge_on_face(i, j))
        queue.push({c.cost(i, j, o.shape_weight, o.sampling_weight), i, j, c.stamp(i)});
  };
  for (std::uint32_t i = 0; i < c.size(); ++i) push_out(i);
  while (c.alive_faces() > 0 && !queue.empty()) {
    const Candidate e = queue.top();
    queue.pop();
    if (!c.alive(e.from) || !c.alive(e.to) || c.stamp(e.from) != e.stamp) continue;
    if (!c.edge_on_face(e.from, e.to)) continue;
    c.collapse(e.from, e.to);
    ++collapses;
    c.bump(e.to);
    push_out(e.to);
    for (std::uint32_t k : c.neighbours(e.to)) {
      c.bump(k);
      push_out(k);
    }
  }
}

void group_nodes(Complex& c, const SurgeryOptions& o, std::size_t& groupings) {
  if (o.grouping_global <= 0.0 && o.grouping_local <= 0.0) return;
  bool changed = true;
  while (changed) {
    changed = false;
    std::vector<std::pair<double, std::array<std::uint32_t, 2>>> edges;
    for (std::uint32_t i = 0; i < c.size(); ++i)
      if (c.alive(i))
        for (std::uint32_t j : c.neighbours(i))
          if (i < j) edges.push_back({glm::length(c.embedded(i) - c.embedded(j)), {i, j}});
    std::sort(edges.begin(), edges.end());
    for (const auto& [length, e] : edges) {
      const auto [a, b] = e;
      if (!c.alive(a) || !c.alive(b) || !contains(c.neighbours(a), b)) continue;
      if (glm::length(c.embedded(a) - c.embedded(b)) != length) continue;  // moved; next pass
      // The node representing fewer vertices goes into the other one.
      const bool a_goes = c.members(a).size() < c.members(b).size() ||
                          (c.members(a).size() == c.members(b).size() && a > b);
      const std::uint32_t from = a_goes ? a : b, to = a_goes ? b : a;
      const double dt = o.grouping_global + o.grouping_local * c.radius(from);
      if (!(length < dt) || c.share_neighbour(from, to)) continue;
      c.collapse(from, to);
      ++groupings;
      changed = true;
    }
  }
}

}  // namespace

CurveGraph collapse_to_curves(const Mesh& contracted, std::span<const float> radius,
                              std::span<const glm::vec3> centres, const SurgeryOptions& options) {
  Complex c(contracted, radius, centres);
  CurveGraph g;
  remove_all_faces(c, options, g.collapses);
  group_nodes(c, options, g.groupings);

  std::vector<std::uint32_t> index(c.size(), UINT32_MAX);
  for (std::uint32_t i = 0; i < c.size(); ++i) {
    if (!c.alive(i)) continue;
    index[i] = static_cast<std::uint32_t>(g.positions.size());
    g.positions.push_back(glm::vec3(c.position(i)));
    g.members.push_back(c.members(i));
  }
  for (std::uint32_t i = 0; i < c.size(); ++i)
    if (c.alive(i))
      for (std::uint32_t j : c.neighbours(i))
        if (i < j) g.edges.push_back({std::min(index[i], index[j]), std::max(index[i], index[j])});
  std::sort(g.edges.begin(), g.edges.end());
  return g;
}

}  // namespace sdfkit::skeleton::detail

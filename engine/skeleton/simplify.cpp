#include "simplify.hpp"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <cmath>
#include <queue>

namespace sdfkit::skeleton::detail {
namespace {

// Collapse cost: the quadric error at the new position plus kLengthWeight |a - b|^4 (both in
// length^4: the quadrics are area-weighted). Quadric error alone collapses flat and straight
// regions into long slivers of far-apart vertices (measured: capsule sides merged into one
// vertex 2 tube radii from some of its input vertices), which breaks the locality of the vertex
// map; the length term keeps the proxy close to uniform until the quadric error of an edge of
// length h on a part of radius r (~ h^6 / r^2) outweighs it, i.e. until h approaches r, so thin
// parts keep their vertices.
constexpr double kLengthWeight = 1.0;
// A collapse must not turn a remaining triangle by more than acos(kMinNormalDot) (~78 deg).
constexpr double kMinNormalDot = 0.2;
// ... nor leave it with a shape quality 4 sqrt(3) A / (sum of squared edges) (1 = equilateral)
// below this, unless it was already worse: slivers make cotangent weights explode.
constexpr double kMinQuality = 0.05;

// Symmetric 4x4 quadric of squared distances to planes, upper triangle row by row:
// a2 ab ac ad b2 bc bd c2 cd d2 for the plane a x + b y + c z + d = 0.
struct Quadric {
  double q[10] = {};
  static Quadric plane(const glm::dvec3& n, double d, double weight) {
    Quadric r;
    const double v[4] = {n.x, n.y, n.z, d};
    int k = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = i; j < 4; ++j) r.q[k++] = weight * v[i] * v[j];
    return r;
  }
  Quadric& operator+=(const Quadric& o) {
    for (int i = 0; i < 10; ++i) q[i] += o.q[i];
    return *this;
  }
  double eval(const glm::dvec3& p) const {
    const double x = p.x, y = p.y, z = p.z;
    return q[0] * x * x + 2 * q[1] * x * y + 2 * q[2] * x * z + 2 * q[3] * x + q[4] * y * y +
           2 * q[5] * y * z + 2 * q[6] * y + q[7] * z * z + 2 * q[8] * z + q[9];
  }
};

// The point minimizing the quadric: the stationary point of the full 3x3 system when it is
// well conditioned and not far from the edge, else the minimum on the segment a-b.
glm::dvec3 best_position(const Quadric& Q, const glm::dvec3& a, const glm::dvec3& b) {
  const double* q = Q.q;
  const glm::dmat3 A(q[0], q[1], q[2], q[1], q[4], q[5], q[2], q[5], q[7]);  // symmetric
  const double det = glm::determinant(A);
  const double scale = (q[0] + q[4] + q[7]) / 3.0;
  const double edge = glm::length(b - a);
  if (scale > 0.0 && std::abs(det) > 1e-3 * scale * scale * scale) {
    const glm::dvec3 p = glm::inverse(A) * (-glm::dvec3(q[3], q[6], q[8]));
    if (glm::length(p - 0.5 * (a + b)) <= edge) return p;
  }
  // On the segment: cost(t) = Q(a + t e) is a quadratic c2 t^2 + c1 t + c0.
  const glm::dvec3 e = b - a;
  const double c0 = Q.eval(a), c1p = Q.eval(a + e), cm = Q.eval(a + 0.5 * e);
  // From three samples: c(0) = c0, c(1/2) = cm, c(1) = c1p.
  const double c2 = 2.0 * (c1p + c0 - 2.0 * cm), c1 = c1p - c0 - c2;
  double t = 0.5;
  if (c2 > 1e-300) t = std::clamp(-c1 / (2.0 * c2), 0.0, 1.0);
  else t = c1p < c0 ? 1.0 : 0.0;
  return a + t * e;
}

double quality(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const double l = glm::dot(b - a, b - a) + glm::dot(c - b, c - b) + glm::dot(a - c, a - c);
  return l > 0.0 ? 2.0 * std::sqrt(3.0) * glm::length(glm::cross(b - a, c - a)) / l : 0.0;
}

struct Candidate {
  double cost;
  std::uint32_t a, b;            // collapse b into a
  std::uint32_t stamp_a, stamp_b;
  bool operator>(const Candidate& o) const { return cost > o.cost; }
};

class Simplifier {
public:
  explicit Simplifier(const Mesh& mesh)
      : faces_(mesh.triangles), face_alive_(mesh.triangles.size(), 1),
        vertex_faces_(mesh.positions.size()), quadric_(mesh.positions.size()),
        stamp_(mesh.positions.size(), 0), alive_(mesh.positions.size(), 0),
        parent_(mesh.positions.size()) {
    pos_.reserve(mesh.positions.size());
    for (const glm::vec3& p : mesh.positions) pos_.emplace_back(p);
    for (std::uint32_t v = 0; v < parent_.size(); ++v) parent_[v] = v;
    for (std::uint32_t f = 0; f < faces_.size(); ++f) {
      const Triangle& t = faces_[f];
      const glm::dvec3 n = glm::cross(pos_[t[1]] - pos_[t[0]], pos_[t[2]] - pos_[t[0]]);
      const double len = glm::length(n);
      for (std::uint32_t v : t) {
        vertex_faces_[v].push_back(f);
        alive_[v] = 1;
      }
      if (!(len > 0.0)) continue;
      // Area-weighted plane quadric: the squared distance to the plane times the face area.
      const Quadric k = Quadric::plane(n / len, -glm::dot(n / len, pos_[t[0]]), 0.5 * len);
      for (std::uint32_t v : t) quadric_[v] += k;
    }
    for (std::uint8_t a : alive_) live_ += a;
  }

  std::size_t live() const { return live_; }
  std::size_t collapses = 0, refused = 0;

  // Collapses the cheapest legal edges until `target` vertices are left or none is legal.
  void run(std::size_t target) {
    while (live_ > target) {
      const std::size_t before = collapses;
      fill_queue();
      while (live_ > target && !queue_.empty()) {
        const Candidate c = queue_.top();
        queue_.pop();
        if (!alive_[c.a] || !alive_[c.b] || stamp_[c.a] != c.stamp_a || stamp_[c.b] != c.stamp_b)
          continue;
        const glm::dvec3 p = best_position(merged(c.a, c.b), pos_[c.a], pos_[c.b]);
        if (!legal(c.a, c.b, p)) {
          ++refused;
          continue;
        }
        collapse(c.a, c.b, p);
      }
      // A refused candidate can become legal after its neighbours changed: one more pass over
      // all edges, until a pass collapses nothing.
      if (collapses == before) break;
    }
  }

  Simplified result() const {
    Simplified s;
    std::vector<std::uint32_t> index(pos_.size(), UINT32_MAX);
    for (std::uint32_t v = 0; v < pos_.size(); ++v)
      if (alive_[v]) {
        index[v] = static_cast<std::uint32_t>(s.mesh.positions.size());
        s.mesh.positions.emplace_back(pos_[v]);
      }
    for (std::uint32_t f = 0; f < faces_.size(); ++f)
      if (face_alive_[f])
        s.mesh.triangles.push_back({index[faces_[f][0]], index[faces_[f][1]], index[faces_[f][2]]});
    s.vertex_map.resize(pos_.size());
    for (std::uint32_t v = 0; v < pos_.size(); ++v) {
      std::uint32_t r = v;
      while (parent_[r] != r) r = parent_[r];
      s.vertex_map[v] = index[r] == UINT32_MAX ? 0 : index[r];
    }
    s.collapses = collapses;
    s.refused = refused;
    return s;
  }

private:
  Quadric merged(std::uint32_t a, std::uint32_t b) const {
    Quadric q = quadric_[a];
    q += quadric_[b];
    return q;
  }

  // Sorted neighbours of v over its live faces, into n (reused storage).
  void neighbours(std::uint32_t v, std::vector<std::uint32_t>& n) const {
    n.clear();
    for (std::uint32_t f : vertex_faces_[v])
      if (face_alive_[f])
        for (std::uint32_t w : faces_[f])
          if (w != v) n.push_back(w);
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }

  // Live faces around v: its number of neighbours on a closed manifold.
  std::size_t live_faces(std::uint32_t v) const {
    std::size_t c = 0;
    for (std::uint32_t f : vertex_faces_[v]) c += face_alive_[f];
    return c;
  }

  void push(std::uint32_t a, std::uint32_t b) {
    const glm::dvec3 p = best_position(merged(a, b), pos_[a], pos_[b]);
    const double l2 = glm::dot(pos_[a] - pos_[b], pos_[a] - pos_[b]);
    queue_.push({std::max(0.0, merged(a, b).eval(p)) + kLengthWeight * l2 * l2, a, b, stamp_[a], stamp_[b]});
  }

  void fill_queue() {
    queue_ = {};
    for (std::uint32_t f = 0; f < faces_.size(); ++f) {
      if (!face_alive_[f]) continue;
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = faces_[f][k], b = faces_[f][(k + 1) % 3];
        if (a < b) push(a, b);  // each edge once: its two faces see it in opposite directions
      }
    }
  }

  bool legal(std::uint32_t a, std::uint32_t b, const glm::dvec3& p) const {
    // The two faces on the edge and their opposite vertices.
    std::uint32_t opposite[2];
    int shared = 0;
    for (std::uint32_t f : vertex_faces_[a]) {
      if (!face_alive_[f]) continue;
      const Triangle& t = faces_[f];
      if (t[0] != b && t[1] != b && t[2] != b) continue;
      if (shared == 2) return false;  // non-manifold edge
      for (std::uint32_t w : t)
        if (w != a && w != b) opposite[shared] = w;
      ++shared;
    }
    if (shared != 2 || opposite[0] == opposite[1]) return false;
    // Link condition: the common neighbours are exactly the two opposite vertices.
    std::vector<std::uint32_t>& na = scratch_a_;
    std::vector<std::uint32_t>& nb = scratch_b_;
    neighbours(a, na);
    neighbours(b, nb);
    std::size_t common = 0;
    for (auto i = na.begin(), j = nb.begin(); i != na.end() && j != nb.end();) {
      if (*i < *j) ++i;
      else if (*j < *i) ++j;
      else ++common, ++i, ++j;
    }
    if (common != 2) return false;
    // Every vertex keeps at least three neighbours.
    if (na.size() + nb.size() < 7) return false;  // merged degree |na| + |nb| - 4 >= 3
    for (std::uint32_t o : opposite)
      if (live_faces(o) < 4) return false;  // o loses one neighbour
    // No face around the merged vertex turns over, degenerates or becomes a sliver.
    for (std::uint32_t v : {a, b})
      for (std::uint32_t f : vertex_faces_[v]) {
        if (!face_alive_[f]) continue;
        const Triangle& t = faces_[f];
        if ((t[0] == a || t[1] == a || t[2] == a) && (t[0] == b || t[1] == b || t[2] == b)) continue;
        glm::dvec3 q[3], old[3];
        for (int k = 0; k < 3; ++k) {
          old[k] = pos_[t[k]];
          q[k] = t[k] == v ? p : pos_[t[k]];
        }
        const glm::vec3 fq[3] = {glm::vec3(q[0]), glm::vec3(q[1]), glm::vec3(q[2])};
        if (triangle_is_degenerate(fq[0], fq[1], fq[2])) return false;
        const glm::dvec3 n_old = glm::cross(old[1] - old[0], old[2] - old[0]);
        const glm::dvec3 n_new = glm::cross(q[1] - q[0], q[2] - q[0]);
        const double lo = glm::length(n_old), ln = glm::length(n_new);
        if (lo > 0.0 && glm::dot(n_old, n_new) < kMinNormalDot * lo * ln) return false;
        const double qn = quality(q[0], q[1], q[2]);
        if (qn < kMinQuality && qn < quality(old[0], old[1], old[2])) return false;
      }
    return true;
  }

  void collapse(std::uint32_t a, std::uint32_t b, const glm::dvec3& p) {
    for (std::uint32_t f : vertex_faces_[b]) {
      if (!face_alive_[f]) continue;
      Triangle& t = faces_[f];
      if (t[0] == a || t[1] == a || t[2] == a) {
        face_alive_[f] = 0;
        continue;
      }
      for (std::uint32_t& w : t)
        if (w == b) w = a;
      vertex_faces_[a].push_back(f);
    }
    std::erase_if(vertex_faces_[a], [&](std::uint32_t f) { return !face_alive_[f]; });
    vertex_faces_[b].clear();
    quadric_[a] += quadric_[b];
    pos_[a] = p;
    alive_[b] = 0;
    parent_[b] = a;
    --live_;
    ++collapses;
    ++stamp_[a];
    ++stamp_[b];
    neighbours(a, scratch_a_);
    for (std::uint32_t w : scratch_a_) push(std::min(a, w), std::max(a, w));
  }

  std::vector<glm::dvec3> pos_;
  std::vector<Triangle> faces_;
  std::vector<std::uint8_t> face_alive_;
  std::vector<std::vector<std::uint32_t>> vertex_faces_;
  std::vector<Quadric> quadric_;
  std::vector<std::uint32_t> stamp_;
  std::vector<std::uint8_t> alive_;
  std::vector<std::uint32_t> parent_;
  std::size_t live_ = 0;
  mutable std::vector<std::uint32_t> scratch_a_, scratch_b_;  // neighbour lists, reused
  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<>> queue_;
};

}  // namespace

Simplified simplify(const Mesh& mesh, std::size_t target_vertices) {
  Simplifier s(mesh);
  s.run(target_vertices);
  return s.result();
}

}  // namespace sdfkit::skeleton::detail

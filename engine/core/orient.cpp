#include "sdfkit/core/orient.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>

namespace sdfkit {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

bool degenerate(const Triangle& t) { return t[0] == t[1] || t[1] == t[2] || t[2] == t[0]; }

// Half-edge h = 3 f + k runs from corner k of face f to corner k + 1.
struct HalfEdges {
  std::vector<std::uint32_t> start;  // per vertex, into `out`
  std::vector<std::uint32_t> out;    // half-edges leaving each vertex
};

HalfEdges half_edges_by_source(const Mesh& mesh) {
  HalfEdges he;
  const std::size_t V = mesh.positions.size();
  he.start.assign(V + 1, 0);
  for (const Triangle& t : mesh.triangles)
    if (!degenerate(t))
      for (std::uint32_t v : t) ++he.start[v + 1];
  std::partial_sum(he.start.begin(), he.start.end(), he.start.begin());
  he.out.resize(he.start[V]);
  std::vector<std::uint32_t> fill(he.start.begin(), he.start.end() - 1);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const Triangle& t = mesh.triangles[f];
    if (degenerate(t)) continue;
    for (std::uint32_t k = 0; k < 3; ++k) he.out[fill[t[k]]++] = static_cast<std::uint32_t>(3 * f + k);
  }
  return he;
}

// The solid angle of triangle (a, b, c) seen from q (Van Oosterom and Strackee), signed by its
// winding.
double solid_angle(const glm::dvec3& q, const glm::dvec3& a0, const glm::dvec3& b0, const glm::dvec3& c0) {
  const glm::dvec3 a = a0 - q, b = b0 - q, c = c0 - q;
  const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  const double num = glm::dot(a, glm::cross(b, c));
  const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
  return 2.0 * std::atan2(num, den);
}

}  // namespace

std::string OrientReport::summary() const {
  std::string s;
  if (flipped_faces > 0) {
    s = "flipped " + std::to_string(flipped_faces) + " faces to wind every piece coherently and outward (";
    std::string why;
    if (incoherent_pieces > 0) why += std::to_string(incoherent_pieces) + " of " + std::to_string(pieces) + " pieces mixed windings";
    if (inverted_pieces > 0)
      why += (why.empty() ? "" : ", ") + std::to_string(inverted_pieces) + " of " + std::to_string(pieces) + " pieces were inside out";
    s += why + ")";
  }
  if (non_orientable_pieces > 0)
    s += (s.empty() ? "" : "; ") + std::to_string(non_orientable_pieces) +
         " pieces cannot be oriented (one-sided surfaces) and keep their windings";
  return s;
}

OrientReport orient_outward(Mesh& mesh) {
  OrientReport report;
  const std::size_t F = mesh.triangles.size();
  if (F == 0) return report;
  const HalfEdges he = half_edges_by_source(mesh);
  const auto to = [&](std::uint32_t h) { return mesh.triangles[h / 3][(h % 3 + 1) % 3]; };
  const auto from = [&](std::uint32_t h) { return mesh.triangles[h / 3][h % 3]; };
  // The one other use of h's edge when exactly two faces use it: (half-edge, same direction).
  const auto partner = [&](std::uint32_t h, std::uint32_t& other, bool& same) {
    const std::uint32_t a = from(h), b = to(h);
    std::size_t uses = 1;
    for (std::uint32_t i = he.start[b]; i < he.start[b + 1]; ++i)
      if (to(he.out[i]) == a) ++uses, other = he.out[i], same = false;
    for (std::uint32_t i = he.start[a]; i < he.start[a + 1]; ++i)
      if (he.out[i] != h && to(he.out[i]) == b) ++uses, other = he.out[i], same = true;
    return uses == 2;
  };

  // Pieces, breadth first; parity 1 = wound against the piece's first face.
  std::vector<std::uint32_t> piece(F, kNone);
  std::vector<std::uint8_t> parity(F, 0);
  std::vector<std::uint8_t> closed, incoherent, orientable;
  std::deque<std::uint32_t> queue;
  for (std::uint32_t seed = 0; seed < F; ++seed) {
    if (piece[seed] != kNone || degenerate(mesh.triangles[seed])) continue;
    const auto id = static_cast<std::uint32_t>(closed.size());
    closed.push_back(1), incoherent.push_back(0), orientable.push_back(1);
    piece[seed] = id;
    queue.push_back(seed);
    while (!queue.empty()) {
      const std::uint32_t f = queue.front();
      queue.pop_front();
      for (std::uint32_t k = 0; k < 3; ++k) {
        std::uint32_t other = 0;
        bool same = false;
        if (!partner(3 * f + k, other, same)) {
          closed[id] = 0;
          continue;
        }
        const std::uint32_t g = other / 3;
        const auto want = static_cast<std::uint8_t>(parity[f] ^ static_cast<std::uint8_t>(same));
        if (piece[g] == kNone) {
          piece[g] = id;
          parity[g] = want;
          incoherent[id] |= want;
          queue.push_back(g);
        } else if (parity[g] != want) {
          orientable[id] = 0;
        }
      }
    }
  }
  const std::size_t P = closed.size();
  report.pieces = P;

  // Per piece: signed volume (parity applied), face areas by parity, bounding box, a surface point.
  std::vector<double> volume(P, 0.0), area0(P, 0.0), area1(P, 0.0), best_area(P, -1.0);
  std::vector<glm::dvec3> ref(P), point(P), lo(P, glm::dvec3(std::numeric_limits<double>::infinity())),
      hi(P, glm::dvec3(-std::numeric_limits<double>::infinity()));
  std::vector<std::uint8_t> has_ref(P, 0);
  for (std::size_t f = 0; f < F; ++f) {
    const std::uint32_t p = piece[f];
    if (p == kNone) continue;
    const Triangle& t = mesh.triangles[f];
    const glm::dvec3 a(mesh.positions[t[0]]), b(mesh.positions[t[1]]), c(mesh.positions[t[2]]);
    if (!has_ref[p]) ref[p] = a, has_ref[p] = 1;
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double area = 0.5 * glm::length(n);
    const double sign = parity[f] ? -1.0 : 1.0;
    volume[p] += sign * glm::dot(a - ref[p], glm::cross(b - ref[p], c - ref[p])) / 6.0;
    (parity[f] ? area1 : area0)[p] += area;
    if (area > best_area[p]) best_area[p] = area, point[p] = (a + b + c) / 3.0;
    lo[p] = glm::min(lo[p], glm::min(a, glm::min(b, c)));
    hi[p] = glm::max(hi[p], glm::max(a, glm::max(b, c)));
  }

  // Faces per closed orientable piece, for the winding numbers.
  std::vector<std::vector<std::uint32_t>> faces_of;
  const auto depth_of = [&](std::uint32_t p) {
    if (faces_of.empty()) {
      faces_of.resize(P);
      for (std::uint32_t f = 0; f < F; ++f)
        if (piece[f] != kNone && closed[piece[f]] && orientable[piece[f]]) faces_of[piece[f]].push_back(f);
    }
    const glm::dvec3 q = point[p];
    std::size_t depth = 0;
    for (std::uint32_t o = 0; o < P; ++o) {
      if (o == p || faces_of[o].empty()) continue;
      if (glm::any(glm::lessThan(q, lo[o])) || glm::any(glm::greaterThan(q, hi[o]))) continue;
      double omega = 0.0;
      for (std::uint32_t f : faces_of[o]) {
        const Triangle& t = mesh.triangles[f];
        const double w = solid_angle(q, glm::dvec3(mesh.positions[t[0]]), glm::dvec3(mesh.positions[t[1]]),
                                     glm::dvec3(mesh.positions[t[2]]));
        omega += parity[f] ? -w : w;
      }
      if (std::abs(omega) > 2.0 * 3.141592653589793) ++depth;  // |winding number| > 1/2
    }
    return depth;
  };

  // Each piece's final sign: flip[p] = 1 turns its parity-0 faces (else its parity-1 faces).
  std::vector<std::uint8_t> flip_zero(P, 0);
  for (std::uint32_t p = 0; p < P; ++p) {
    if (!orientable[p]) {
      ++report.non_orientable_pieces;
      continue;
    }
    if (closed[p] && volume[p] != 0.0) {
      if (incoherent[p]) {
        const bool solid = depth_of(p) % 2 == 0;
        flip_zero[p] = (volume[p] > 0.0) != solid;
        ++report.incoherent_pieces;
      } else if (volume[p] < 0.0 && depth_of(p) == 0) {
        flip_zero[p] = 1;
        ++report.inverted_pieces;
      }
    } else if (incoherent[p]) {
      flip_zero[p] = area1[p] > area0[p];
      ++report.incoherent_pieces;
    }
  }
  for (std::size_t f = 0; f < F; ++f) {
    const std::uint32_t p = piece[f];
    if (p == kNone || !orientable[p] || parity[f] == flip_zero[p]) continue;
    std::swap(mesh.triangles[f][1], mesh.triangles[f][2]);
    ++report.flipped_faces;
  }
  return report;
}

}  // namespace sdfkit

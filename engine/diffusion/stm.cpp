// Skeleton texture mapping: charts from a skeleton, their parameterizations, packing, quality.
// The road (build_stm): vertex → node ──▶ bones (chains between joints) with rotation-minimizing
// frames ──▶ each vertex to a bone, an end cap or a planar region ──▶ demote the vertices of
// stretched or flipped triangles to planar regions (repeat) ──▶ planar regions split into charts
// by normal direction ──▶ atlas triangles (one per face and chart it touches) ──▶ overlap bands,
// and conformal maps (LSCM) for the joint and sheet charts over their faces and bands ──▶ chart
// extents ──▶ scale and shelf packing ──▶ texel coordinates ──▶ quality.
#include "sdfkit/diffusion/stm.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/topology.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>
#include <unordered_map>

namespace sdfkit::diffusion {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
constexpr double kTwoPi = 6.283185307179586;
// Angle distortion of a triangle mapped to a segment or point (σ2 = 0), and the cap of all.
constexpr double kMaxAngleDistortion = 1000.0;
// A connected piece of a bone's region with fewer vertices than this is charted as a planar joint.
constexpr std::size_t kMinBonePiece = 12;

// A skeleton segment between joints: the polyline through its nodes' positions, arc length at
// each point, and a rotation-minimizing frame (n, b) per segment (double reflection, Wang et al.
// 2008), t = the segment's direction.
struct Bone {
  std::vector<std::uint32_t> nodes;  // first and last are joints (or the same node, for a loop)
  std::vector<glm::dvec3> points;
  std::vector<double> s;             // arc length at each point
  std::vector<glm::dvec3> t, n, b;   // per segment
  std::vector<glm::dvec3> m;         // per point: normal of the plane bisecting the bend there
  double length = 0;
  double radius = 0;                 // median distance of its vertices to the polyline
};

// Closest point of p on a bone's polyline.
struct BonePoint {
  double dist = 0, s = 0;
  std::size_t seg = 0;
  bool clamped = false;  // beyond the polyline's first or last point (s extrapolated)
  glm::dvec3 radial{0.0};  // p - closest point
};

// The point of a bone's polyline that p projects to. Between the planes that bisect the
// polyline's bends (normal m_i = the mean of the adjacent segments' directions; at the ends the
// end segment's direction), p belongs to the segment whose slab holds it and is parameterized
// by λ = d0 / (d0 - d1), its signed distances to the slab's planes: continuous across a bend,
// where the plain closest point jumps on the inner side and stalls on the outer side. Several
// slabs can hold p far from the polyline: the one whose point is nearest wins. p in no slab
// (beyond an end): the closest point, clamped.
BonePoint closest_on_bone(const Bone& bone, const glm::dvec3& p) {
  BonePoint best;
  best.dist = std::numeric_limits<double>::infinity();
  const std::size_t segs = bone.t.size();
  for (std::size_t i = 0; i < segs; ++i) {
    const glm::dvec3 a = bone.points[i], b = bone.points[i + 1];
    const double len = bone.s[i + 1] - bone.s[i];
    const double d0 = glm::dot(p - a, bone.m[i]), d1 = glm::dot(p - b, bone.m[i + 1]);
    if (!(d0 >= 0 && d1 <= 0 && d0 - d1 > 0)) continue;
    const double lambda = d0 / (d0 - d1);
    const glm::dvec3 q = a + (b - a) * lambda;
    const double d = glm::length(p - q);
    if (d < best.dist) best = {d, bone.s[i] + lambda * len, i, false, p - q};
  }
  if (std::isfinite(best.dist)) return best;
  for (std::size_t i = 0; i < segs; ++i) {
    const glm::dvec3 a = bone.points[i];
    const double len = bone.s[i + 1] - bone.s[i];
    double x = glm::dot(p - a, bone.t[i]);
    // Beyond an end the polyline is extended along the end segment (a neighbouring chart's
    // vertex keeps its distance from the end instead of collapsing onto it).
    bool clamped = false;
    if (x < 0) {
      clamped = i == 0;
      if (!clamped) x = 0;
    } else if (x > len) {
      clamped = i + 1 == segs;
      if (!clamped) x = len;
    }
    const glm::dvec3 q = a + bone.t[i] * x;
    const double d = glm::length(p - q);
    if (d < best.dist) best = {d, bone.s[i] + x, i, clamped, p - q};
  }
  return best;
}

// Angle of the radial vector around segment `seg`'s frame, in [0, 2π).
double bone_angle(const Bone& bone, std::size_t seg, const glm::dvec3& radial) {
  double a = std::atan2(glm::dot(radial, bone.b[seg]), glm::dot(radial, bone.n[seg]));
  if (a < 0) a += kTwoPi;
  return a >= kTwoPi ? 0.0 : a;
}

glm::dvec3 any_perpendicular(const glm::dvec3& t) {
  const glm::dvec3 ax = std::abs(t.x) <= std::abs(t.y) && std::abs(t.x) <= std::abs(t.z) ? glm::dvec3(1, 0, 0)
                        : std::abs(t.y) <= std::abs(t.z)                                 ? glm::dvec3(0, 1, 0)
                                                                                         : glm::dvec3(0, 0, 1);
  return glm::normalize(glm::cross(t, ax));
}

void build_frames(Bone& bone) {
  const std::size_t segs = bone.points.size() - 1;
  bone.s.assign(bone.points.size(), 0.0);
  for (std::size_t i = 0; i < segs; ++i) {
    const glm::dvec3 d = bone.points[i + 1] - bone.points[i];
    const double len = glm::length(d);
    bone.s[i + 1] = bone.s[i] + len;
    bone.t.push_back(len > 0 ? d / len : (i > 0 ? bone.t[i - 1] : glm::dvec3(0, 0, 1)));
  }
  bone.length = bone.s.back();
  bone.m.resize(bone.points.size());
  bone.m.front() = bone.t.front();
  bone.m.back() = bone.t.back();
  for (std::size_t i = 1; i < segs; ++i) {
    const glm::dvec3 mid = bone.t[i - 1] + bone.t[i];
    const double ml = glm::length(mid);
    bone.m[i] = ml > 1e-9 ? mid / ml : bone.t[i];
  }
  bone.n.resize(segs);
  bone.b.resize(segs);
  bone.n[0] = any_perpendicular(bone.t[0]);
  bone.b[0] = glm::cross(bone.t[0], bone.n[0]);
  for (std::size_t i = 1; i < segs; ++i) {
    // Double reflection between consecutive segment frames, both "located" at the shared point.
    const glm::dvec3 v1 = bone.points[i] - bone.points[i - 1];
    const double c1 = glm::dot(v1, v1);
    glm::dvec3 r = bone.n[i - 1], tl = bone.t[i - 1];
    if (c1 > 0) {
      r -= (2.0 / c1) * glm::dot(v1, r) * v1;
      tl -= (2.0 / c1) * glm::dot(v1, tl) * v1;
    }
    const glm::dvec3 v2 = bone.t[i] - tl;
    const double c2 = glm::dot(v2, v2);
    if (c2 > 1e-24) r -= (2.0 / c2) * glm::dot(v2, r) * v2;
    r -= bone.t[i] * glm::dot(r, bone.t[i]);
    const double rl = glm::length(r);
    bone.n[i] = rl > 1e-12 ? r / rl : any_perpendicular(bone.t[i]);
    bone.b[i] = glm::cross(bone.t[i], bone.n[i]);
  }
}

enum class Region : std::uint8_t { Bone, Cap, Joint, Sheet };

// How a chart maps a model point to its local plane (model units).
struct ChartMap {
  Chart::Kind kind = Chart::Kind::Bone;
  std::uint32_t bone = kNone;   // Bone: index into bones
  double width = 0;             // Bone: 2π × radius (x wraps there when `wraps`)
  double angle0 = 0;            // Bone: the angle at x = 0
  bool wraps = true;            // Bone: the piece goes all around (else x spans the used sector)
  glm::dvec3 origin{0.0}, axis{0.0}, b1{0.0}, b2{0.0};  // Cap / planar
  double cap_radius = 0;        // Cap: ρ = 2 tan(polar angle / 2) × cap_radius (stereographic)
  bool cap = false;
  // Local extent (after collection), model units.
  glm::dvec2 lo{std::numeric_limits<double>::infinity()}, hi{-std::numeric_limits<double>::infinity()};
};

glm::dvec2 local_coords(const ChartMap& c, const std::vector<Bone>& bones, const glm::dvec3& p) {
  if (c.kind == Chart::Kind::Bone) {
    const Bone& bone = bones[c.bone];
    const BonePoint bp = closest_on_bone(bone, p);
    double a = bone_angle(bone, bp.seg, bp.radial) - c.angle0;
    if (a < 0) a += kTwoPi;
    return {a / kTwoPi * c.width, bp.s};
  }
  const glm::dvec3 q = p - c.origin;
  if (c.cap) {
    const double lq = glm::length(q);
    if (lq <= 0) return {0, 0};
    const double polar = std::atan2(glm::length(glm::cross(q, c.axis)), glm::dot(q, c.axis));
    const glm::dvec2 dir(glm::dot(q, c.b1), glm::dot(q, c.b2));
    const double dl = glm::length(dir);
    if (dl <= 0) return {0, 0};
    // Stereographic: the conformal map of the sphere of directions around the origin (the
    // azimuthal equidistant map, ρ = polar × cap_radius, is not). The blur follows a conformal
    // map's Laplace-Beltrami operator, λ⁻² Δ, with its per-texel width alone; a non-conformal map
    // adds a drift term (Δ of the chart's coordinates) that no blur width carries. On a unit
    // sphere, six cap charts, u = z (exact answer z e^(-σ²)), read from their own charts: RMS error
    // 16-20 % of the change at 1-5 edges with the equidistant map, 0.1-0.4 % with this one.
    return dir / dl * (2.0 * std::tan(0.5 * polar) * c.cap_radius);
  }
  return {glm::dot(q, c.b1), glm::dot(q, c.b2)};
}

// Unwraps x of wrapping-chart corners toward the reference corner's x.
void unwrap(glm::dvec2 (&uv)[3], int ref, double width) {
  for (int k = 0; k < 3; ++k)
    if (k != ref) uv[k].x += width * std::round((uv[ref].x - uv[k].x) / width);
}

double signed_area2(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// Area-weighted mean, 95th percentile and maximum.
Stats weighted_stats(std::vector<std::pair<double, double>> value_weight) {
  Stats st;
  if (value_weight.empty()) return st;
  std::sort(value_weight.begin(), value_weight.end());
  double wsum = 0, vsum = 0;
  for (const auto& [v, w] : value_weight) wsum += w, vsum += v * w;
  st.mean = wsum > 0 ? vsum / wsum : value_weight.front().first;
  st.max = value_weight.back().first;
  double acc = 0;
  st.p95 = st.max;
  for (const auto& [v, w] : value_weight) {
    acc += w;
    if (wsum > 0 && acc >= 0.95 * wsum) {
      st.p95 = v;
      break;
    }
  }
  return st;
}

struct Packed {
  std::vector<std::uint32_t> x, y, w, h;
  bool fits = false;
};

// Shelf packing: rectangles sorted by height (then width, then index), placed left to right in
// rows; `gutter` texels between rectangles and along the atlas border.
Packed shelf_pack(const std::vector<std::uint32_t>& w, const std::vector<std::uint32_t>& h, std::uint32_t size,
                  std::uint32_t gutter) {
  Packed p;
  p.w = w;
  p.h = h;
  p.x.assign(w.size(), 0);
  p.y.assign(w.size(), 0);
  std::vector<std::uint32_t> order(w.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    if (h[a] != h[b]) return h[a] > h[b];
    if (w[a] != w[b]) return w[a] > w[b];
    return a < b;
  });
  std::uint64_t x = gutter, y = gutter, row_h = 0;
  for (std::uint32_t i : order) {
    if (w[i] + 2ull * gutter > size) return p;
    if (x + w[i] + gutter > size) {
      y += row_h + gutter;
      x = gutter;
      row_h = 0;
    }
    if (y + h[i] + gutter > size) return p;
    p.x[i] = static_cast<std::uint32_t>(x);
    p.y[i] = static_cast<std::uint32_t>(y);
    x += w[i] + gutter;
    row_h = std::max<std::uint64_t>(row_h, h[i]);
  }
  p.fits = true;
  return p;
}

// Singular values (σ1 ≥ σ2) of the 2×2 matrix [a b; c d].
std::pair<double, double> singular_values(double a, double b, double c, double d) {
  const double e = (a + d) / 2, f = (a - d) / 2, g = (c + b) / 2, h = (c - b) / 2;
  const double q = std::hypot(e, h), r = std::hypot(f, g);
  return {q + r, std::abs(q - r)};
}

// Triangle (p0, p1, p2) in its own plane: p0 at the origin, p1 on the x axis at l1 = |p1 - p0|,
// p2 at (ex, ey), ey > 0 on the side the triangle's normal (p1 - p0) × (p2 - p0) sees it
// counter-clockwise; `twice_area` = |(p1 - p0) × (p2 - p0)|. Nothing for a degenerate triangle
// (l1 or the area 0).
struct PlaneTriangle {
  double l1, ex, ey, twice_area;
};
std::optional<PlaneTriangle> in_own_plane(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2) {
  const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0, n = glm::cross(e1, e2);
  const double l1 = glm::length(e1), an = glm::length(n);
  if (!(l1 > 0) || !(an > 0)) return std::nullopt;
  const glm::dvec3 ux = e1 / l1, uy = glm::cross(n / an, ux);
  return PlaneTriangle{l1, glm::dot(e2, ux), glm::dot(e2, uy), an};
}

// σ1 ≥ σ2 of the linear map taking triangle (p0, p1, p2), in its own plane, to the chart points
// uv (chart units per model unit); nothing for a degenerate triangle.
std::optional<std::pair<double, double>> face_map_singular_values(const glm::dvec3& p0, const glm::dvec3& p1,
                                                                  const glm::dvec3& p2, const glm::dvec2 (&uv)[3]) {
  const std::optional<PlaneTriangle> q = in_own_plane(p0, p1, p2);
  if (!q) return std::nullopt;
  // P = [p1 p2] in the triangle's plane, D = [d1 d2] in the chart: J = D P^-1, with
  // P^-1 = [[1/l1, -ex/(l1 ey)], [0, 1/ey]].
  const glm::dvec2 d1 = uv[1] - uv[0], d2 = uv[2] - uv[0];
  const double j11 = d1.x / q->l1, j21 = d1.y / q->l1;
  const double j12 = (d2.x - q->ex * j11) / q->ey, j22 = (d2.y - q->ex * j21) / q->ey;
  return singular_values(j11, j12, j21, j22);
}

}  // namespace

// Whether two triangles of a plane overlap by more than `eps` (separating axes over their six
// edge normals; triangles that only touch along an edge or at a corner do not).
bool triangles_overlap(const glm::dvec2 (&a)[3], const glm::dvec2 (&b)[3], double eps) {
  // Bounding boxes first (most pairs of a grid cell are apart), then the edge normals.
  const glm::dvec2 alo = glm::min(glm::min(a[0], a[1]), a[2]), ahi = glm::max(glm::max(a[0], a[1]), a[2]);
  const glm::dvec2 blo = glm::min(glm::min(b[0], b[1]), b[2]), bhi = glm::max(glm::max(b[0], b[1]), b[2]);
  if (ahi.x - blo.x <= eps || bhi.x - alo.x <= eps || ahi.y - blo.y <= eps || bhi.y - alo.y <= eps) return false;
  for (int pass = 0; pass < 2; ++pass) {
    const glm::dvec2(&t)[3] = pass == 0 ? a : b;
    for (int k = 0; k < 3; ++k) {
      const glm::dvec2 e = t[(k + 1) % 3] - t[k];
      const glm::dvec2 n(-e.y, e.x);  // unnormalized: projections and eps scale by |n|
      const double len = std::sqrt(n.x * n.x + n.y * n.y);
      if (!(len > 0)) continue;
      double amin = 1e300, amax = -1e300, bmin = 1e300, bmax = -1e300;
      for (int i = 0; i < 3; ++i) {
        const double pa = glm::dot(a[i], n), pb = glm::dot(b[i], n);
        amin = std::min(amin, pa), amax = std::max(amax, pa), bmin = std::min(bmin, pb), bmax = std::max(bmax, pb);
      }
      if (amax - bmin <= eps * len || bmax - amin <= eps * len) return false;
    }
  }
  return true;
}

namespace {

// Flags the triangles (chart coordinates, model units) that overlap another one they share no
// corner with, by more than `eps`: where a chart's map is not one-to-one, so that texels there
// would carry two parts of the surface. `corners`: each triangle's mesh vertices; `period` > 0:
// x wraps with that period (a bone chart). A uniform grid of `cell`-sized cells; a triangle over
// more than 4096 cells is not tested.
std::vector<std::uint8_t> overlapping_triangles(const std::vector<std::array<glm::dvec2, 3>>& uv,
                                                const std::vector<Triangle>& corners, double period, double cell, double eps) {
  struct Entry {
    std::uint64_t key;
    std::uint32_t tri;
    std::int32_t shift;  // in periods
  };
  std::vector<Entry> entries;
  const auto shifted = [&](std::uint32_t i, std::int32_t k, glm::dvec2 (&out)[3]) {
    for (int c = 0; c < 3; ++c) out[c] = uv[i][static_cast<std::size_t>(c)] + glm::dvec2(k * period, 0.0);
  };
  for (std::uint32_t i = 0; i < uv.size(); ++i)
    for (std::int32_t k = period > 0 ? -1 : 0; k <= (period > 0 ? 1 : 0); ++k) {
      glm::dvec2 t[3];
      shifted(i, k, t);
      const glm::dvec2 lo = glm::min(glm::min(t[0], t[1]), t[2]), hi = glm::max(glm::max(t[0], t[1]), t[2]);
      if (!std::isfinite(lo.x + lo.y + hi.x + hi.y)) continue;
      const double x0 = std::floor(lo.x / cell), x1 = std::floor(hi.x / cell), y0 = std::floor(lo.y / cell), y1 = std::floor(hi.y / cell);
      if ((x1 - x0 + 1) * (y1 - y0 + 1) > 4096) continue;
      for (double x = x0; x <= x1; ++x)
        for (double y = y0; y <= y1; ++y)
          entries.push_back({(static_cast<std::uint64_t>(static_cast<std::uint32_t>(static_cast<std::int64_t>(x))) << 32) |
                                 static_cast<std::uint32_t>(static_cast<std::int64_t>(y)),
                             i, k});
    }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.key != b.key ? a.key < b.key : (a.tri != b.tri ? a.tri < b.tri : a.shift < b.shift);
  });
  std::vector<std::uint8_t> flag(uv.size(), 0);
  for (std::size_t a = 0; a < entries.size();) {
    std::size_t b = a;
    while (b < entries.size() && entries[b].key == entries[a].key) ++b;
    for (std::size_t i = a; i < b; ++i)
      for (std::size_t j = i + 1; j < b; ++j) {
        const Entry &p = entries[i], &q = entries[j];
        if (p.tri == q.tri || (flag[p.tri] && flag[q.tri])) continue;
        bool shares = false;
        for (std::uint32_t x : corners[p.tri])
          for (std::uint32_t y : corners[q.tri]) shares = shares || x == y;
        if (shares) continue;
        glm::dvec2 tp[3], tq[3];
        shifted(p.tri, p.shift, tp);
        shifted(q.tri, q.shift, tq);
        if (triangles_overlap(tp, tq, eps)) flag[p.tri] = flag[q.tri] = 1;
      }
    a = b;
  }
  return flag;
}

}  // namespace

Stm build_stm(const Mesh& mesh, const skeleton::Skeleton& skel, const StmOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t V = mesh.positions.size(), F = mesh.triangles.size();
  if (V == 0 || F == 0) throw InputError("skeleton texture mapping: the mesh has no triangles");
  if (skel.nodes.empty()) throw InputError("skeleton texture mapping: the skeleton has no nodes");
  if (options.atlas_size < 16 || options.atlas_size > 16384)
    throw UsageError("skeleton texture mapping: the atlas size must be 16 to 16384 texels");
  if (options.gutter > 64 || 4u * options.gutter + 4 > options.atlas_size)
    throw UsageError("skeleton texture mapping: the gutter must be 0 to 64 texels and leave room in the atlas");
  if (!(options.max_normal_angle_deg > 0 && options.max_normal_angle_deg <= 90))
    throw UsageError("skeleton texture mapping: max_normal_angle_deg must be in (0, 90]");
  if (!(options.max_stretch >= 1.0 && std::isfinite(options.max_stretch)))
    throw UsageError("skeleton texture mapping: max_stretch must be at least 1");
  if (!(options.overlap >= 0.0 && std::isfinite(options.overlap)))
    throw UsageError("skeleton texture mapping: the overlap band must be finite and >= 0 model units");
  for (const Triangle& t : mesh.triangles)
    for (std::uint32_t v : t)
      if (v >= V) throw InputError("skeleton texture mapping: a triangle index is out of range");
  const std::size_t N = skel.nodes.size();
  for (const auto& e : skel.edges)
    if (e[0] >= N || e[1] >= N) throw InputError("skeleton texture mapping: a skeleton edge refers to a missing node");

  // Mesh adjacency (CSR).
  std::vector<std::uint32_t> adj_start(V + 1, 0), adj;
  {
    for (const Triangle& t : mesh.triangles)
      for (int k = 0; k < 3; ++k) adj_start[t[k] + 1] += 2;
    for (std::size_t i = 0; i < V; ++i) adj_start[i + 1] += adj_start[i];
    adj.resize(adj_start[V]);
    std::vector<std::uint32_t> fill(adj_start.begin(), adj_start.end() - 1);
    for (const Triangle& t : mesh.triangles)
      for (int k = 0; k < 3; ++k) {
        adj[fill[t[k]]++] = t[(k + 1) % 3];
        adj[fill[t[k]]++] = t[(k + 2) % 3];
      }
  }

  // 1. Vertex → node; vertices no node holds take a neighbour's node (breadth first), isolated
  // ones the nearest node.
  std::vector<std::uint32_t> vnode(V, kNone);
  std::deque<std::uint32_t> queue;
  for (std::size_t i = 0; i < N; ++i)
    for (std::uint32_t v : skel.nodes[i].vertices) {
      if (v >= V) throw InputError("skeleton texture mapping: skeleton node " + std::to_string(i) +
                                   " holds vertex " + std::to_string(v) + ", the mesh has " + std::to_string(V));
      if (vnode[v] == kNone) vnode[v] = static_cast<std::uint32_t>(i), queue.push_back(v);
    }
  while (!queue.empty()) {
    const std::uint32_t v = queue.front();
    queue.pop_front();
    for (std::uint32_t k = adj_start[v]; k < adj_start[v + 1]; ++k)
      if (vnode[adj[k]] == kNone) vnode[adj[k]] = vnode[v], queue.push_back(adj[k]);
  }
  for (std::size_t v = 0; v < V; ++v)
    if (vnode[v] == kNone) {
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < N; ++i) {
        const double d = glm::length(glm::dvec3(mesh.positions[v]) - glm::dvec3(skel.nodes[i].position));
        if (d < best) best = d, vnode[v] = static_cast<std::uint32_t>(i);
      }
    }

  // 2. Bones: chains of curve nodes of degree 2 between curve nodes of other degree.
  std::vector<std::vector<std::uint32_t>> nbr(N);
  for (const auto& e : skel.edges)
    if (e[0] != e[1] && !skel.nodes[e[0]].sheet && !skel.nodes[e[1]].sheet) {
      nbr[e[0]].push_back(e[1]);
      nbr[e[1]].push_back(e[0]);
    }
  for (auto& l : nbr) {
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
  }
  std::vector<std::uint8_t> joint(N, 0);
  for (std::size_t i = 0; i < N; ++i) joint[i] = !skel.nodes[i].sheet && nbr[i].size() != 2;
  std::vector<Bone> bones;
  std::vector<std::uint32_t> node_bone(N, kNone);  // for interior nodes
  std::vector<std::vector<std::uint32_t>> joint_bones(N);
  std::vector<std::uint8_t> walked(N, 0);
  const auto walk = [&](std::uint32_t from, std::uint32_t next) {
    Bone bone;
    bone.nodes = {from};
    std::uint32_t prev = from, cur = next;
    while (!joint[cur]) {
      walked[cur] = 1;
      bone.nodes.push_back(cur);
      const std::uint32_t nx = nbr[cur][0] == prev ? nbr[cur][1] : nbr[cur][0];
      prev = cur;
      cur = nx;
    }
    bone.nodes.push_back(cur);
    return bone;
  };
  const auto add_bone = [&](Bone bone) {
    for (std::uint32_t n : bone.nodes) bone.points.push_back(glm::dvec3(skel.nodes[n].position));
    build_frames(bone);
    if (!(bone.length > 0)) return;
    const auto id = static_cast<std::uint32_t>(bones.size());
    for (std::size_t k = 1; k + 1 < bone.nodes.size(); ++k) node_bone[bone.nodes[k]] = id;
    joint_bones[bone.nodes.front()].push_back(id);
    if (bone.nodes.back() != bone.nodes.front()) joint_bones[bone.nodes.back()].push_back(id);
    bones.push_back(std::move(bone));
  };
  for (std::uint32_t j = 0; j < N; ++j) {
    if (!joint[j]) continue;
    for (std::uint32_t nb : nbr[j]) {
      if (joint[nb]) {
        if (j < nb) add_bone(walk(j, nb));
        continue;
      }
      if (walked[nb]) continue;
      add_bone(walk(j, nb));
    }
  }
  // Loops of degree-2 nodes: the smallest node becomes a joint where the loop is cut.
  for (std::uint32_t i = 0; i < N; ++i) {
    if (skel.nodes[i].sheet || joint[i] || walked[i] || nbr[i].size() != 2) continue;
    joint[i] = 1;
    walked[i] = 1;
    add_bone(walk(i, nbr[i][0]));
  }

  // 3. Each vertex to a bone, a cap or a planar region.
  const std::vector<glm::vec3> normals = vertex_normals(mesh);
  const double cos_max = std::cos(options.max_normal_angle_deg * kTwoPi / 360.0);
  const double diag = bounding_box(mesh.positions).diagonal();
  std::vector<Region> region(V, Region::Joint);
  std::vector<std::uint32_t> owner(V, kNone);  // bone index (Bone) or node (Cap)
  std::vector<double> radial(V, 0.0);
  for (std::size_t v = 0; v < V; ++v) {
    const std::uint32_t nd = vnode[v];
    if (skel.nodes[nd].sheet) {
      region[v] = Region::Sheet;
      continue;
    }
    std::vector<std::uint32_t> cands;
    if (node_bone[nd] != kNone) cands.push_back(node_bone[nd]);
    else cands = joint_bones[nd];
    if (cands.empty()) continue;  // an isolated node: planar joint region
    const glm::dvec3 p(mesh.positions[v]);
    std::uint32_t bi = kNone;
    BonePoint bp;
    for (std::uint32_t c : cands) {
      const BonePoint q = closest_on_bone(bones[c], p);
      if (bi == kNone || q.dist < bp.dist) bi = c, bp = q;
    }
    const Bone& bone = bones[bi];
    const glm::dvec3 n(normals[v]);
    const double radius = std::max(1e-6 * diag, 0.05 * static_cast<double>(skel.nodes[nd].radius));
    const bool ok = !bp.clamped && bp.dist > radius && std::abs(glm::dot(n, bone.t[bp.seg])) <= cos_max;
    if (ok) {
      region[v] = Region::Bone;
      owner[v] = bi;
      radial[v] = bp.dist;
      continue;
    }
    const std::uint32_t end = bp.s < bone.length / 2 ? bone.nodes.front() : bone.nodes.back();
    if (nbr[end].size() == 1 && bone.nodes.front() != bone.nodes.back()) {
      region[v] = Region::Cap;
      owner[v] = end;
    }
  }

  std::vector<Bone>& B = bones;
  // Per bone radius: median distance of its vertices; per cap: frame at the end.
  const auto bone_radii = [&] {
    std::vector<std::vector<double>> r(B.size());
    for (std::size_t v = 0; v < V; ++v)
      if (region[v] == Region::Bone) r[owner[v]].push_back(radial[v]);
    for (std::size_t b = 0; b < B.size(); ++b) {
      if (r[b].empty()) {
        B[b].radius = 0;
        continue;
      }
      auto mid = r[b].begin() + static_cast<std::ptrdiff_t>(r[b].size() / 2);
      std::nth_element(r[b].begin(), mid, r[b].end());
      B[b].radius = *mid;
    }
  };

  // The charts of the current assignment, rebuilt after every demotion round.
  std::vector<ChartMap> maps;
  std::vector<std::uint32_t> vchart(V, kNone);
  const auto build_charts = [&] {
    maps.clear();
    bone_radii();
    std::vector<std::uint32_t> cap_chart(N, kNone);
    std::fill(vchart.begin(), vchart.end(), kNone);
    std::vector<std::uint32_t> pending;
    for (std::size_t v = 0; v < V; ++v) {
      if (region[v] == Region::Bone) {
        // One chart per connected piece of a bone's vertices (demotions can cut a bone's region
        // in two; one rectangle over both would be mostly empty).
        // Pieces of fewer than kMinBonePiece vertices join the planar joint regions.
        if (vchart[v] != kNone) continue;
        ChartMap m;
        m.kind = Chart::Kind::Bone;
        m.bone = owner[v];
        m.width = kTwoPi * B[owner[v]].radius;
        const auto id = static_cast<std::uint32_t>(maps.size());
        maps.push_back(m);
        vchart[v] = id;
        std::vector<std::uint32_t> piece{static_cast<std::uint32_t>(v)};
        pending = {static_cast<std::uint32_t>(v)};
        while (!pending.empty()) {
          const std::uint32_t a = pending.back();
          pending.pop_back();
          for (std::uint32_t k = adj_start[a]; k < adj_start[a + 1]; ++k) {
            const std::uint32_t b = adj[k];
            if (vchart[b] == kNone && region[b] == Region::Bone && owner[b] == owner[v])
              vchart[b] = id, pending.push_back(b), piece.push_back(b);
          }
        }
        if (piece.size() < kMinBonePiece) {
          maps.pop_back();
          for (std::uint32_t a : piece) vchart[a] = kNone, region[a] = Region::Joint, owner[a] = kNone;
        }
      } else if (region[v] == Region::Cap) {
        std::uint32_t& c = cap_chart[owner[v]];
        if (c == kNone) {
          ChartMap m;
          m.kind = Chart::Kind::Joint;
          m.cap = true;
          const std::uint32_t end = owner[v];
          const Bone& bone = B[joint_bones[end][0]];
          const bool at_front = bone.nodes.front() == end;
          const std::size_t seg = at_front ? 0 : bone.t.size() - 1;
          m.origin = glm::dvec3(skel.nodes[end].position);
          m.axis = at_front ? -bone.t[seg] : bone.t[seg];
          m.b1 = bone.n[seg];
          m.b2 = glm::cross(m.axis, m.b1);
          c = static_cast<std::uint32_t>(maps.size());
          maps.push_back(m);
        }
        vchart[v] = c;
      } else {
        vchart[v] = kNone;
      }
    }
    // A bone piece whose vertices leave a gap of over a quarter turn around the bone does not
    // wrap: its x spans the used sector, with the angle origin in the middle of the gap.
    {
      std::vector<std::vector<double>> angles(maps.size());
      for (std::size_t v = 0; v < V; ++v)
        if (region[v] == Region::Bone && vchart[v] != kNone)
          angles[vchart[v]].push_back(local_coords(maps[vchart[v]], B, glm::dvec3(mesh.positions[v])).x /
                                      std::max(maps[vchart[v]].width, 1e-300) * kTwoPi);
      for (std::size_t c = 0; c < maps.size(); ++c) {
        if (maps[c].kind != Chart::Kind::Bone || angles[c].size() < 2) continue;
        auto& a = angles[c];
        std::sort(a.begin(), a.end());
        double gap = a.front() + kTwoPi - a.back(), mid = a.back() + gap / 2;
        for (std::size_t i = 1; i < a.size(); ++i)
          if (a[i] - a[i - 1] > gap) gap = a[i] - a[i - 1], mid = a[i - 1] + gap / 2;
        if (gap > kTwoPi / 4) {
          maps[c].wraps = false;
          maps[c].angle0 = std::fmod(mid, kTwoPi);
        }
      }
    }
    // Cap radius: mean distance of its vertices to the centre.
    std::vector<double> sum(maps.size(), 0.0), cnt(maps.size(), 0.0);
    for (std::size_t v = 0; v < V; ++v)
      if (region[v] == Region::Cap) {
        sum[vchart[v]] += glm::length(glm::dvec3(mesh.positions[v]) - maps[vchart[v]].origin);
        cnt[vchart[v]] += 1;
      }
    for (std::size_t c = 0; c < maps.size(); ++c)
      if (maps[c].cap) maps[c].cap_radius = cnt[c] > 0 ? sum[c] / cnt[c] : 0;

    // Planar regions: connected components (same kind) of the remaining vertices, each split by
    // the six principal directions of its positions into connected charts.
    std::vector<std::uint32_t> comp(V, kNone);
    std::uint32_t ncomp = 0;
    std::vector<std::uint32_t> stack;
    std::vector<std::vector<std::uint32_t>> members;
    for (std::uint32_t v = 0; v < V; ++v) {
      if (vchart[v] != kNone || comp[v] != kNone) continue;
      members.emplace_back();
      comp[v] = ncomp;
      stack = {v};
      while (!stack.empty()) {
        const std::uint32_t a = stack.back();
        stack.pop_back();
        members.back().push_back(a);
        for (std::uint32_t k = adj_start[a]; k < adj_start[a + 1]; ++k) {
          const std::uint32_t b = adj[k];
          if (vchart[b] == kNone && comp[b] == kNone && region[b] == region[v]) comp[b] = ncomp, stack.push_back(b);
        }
      }
      ++ncomp;
    }
    std::vector<std::uint8_t> cluster(V, 0);
    for (std::uint32_t ci = 0; ci < ncomp; ++ci) {
      const auto& mem = members[ci];
      glm::dvec3 mean(0.0);
      for (std::uint32_t v : mem) mean += glm::dvec3(mesh.positions[v]);
      mean /= static_cast<double>(mem.size());
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (std::uint32_t v : mem) {
        const glm::dvec3 d = glm::dvec3(mesh.positions[v]) - mean;
        const Eigen::Vector3d e(d.x, d.y, d.z);
        cov += e * e.transpose();
      }
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
      glm::dvec3 axes[3];
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d e = es.eigenvectors().col(2 - k);
        axes[k] = glm::dvec3(e.x(), e.y(), e.z());
      }
      if (mem.size() < 3 || !std::isfinite(axes[0].x)) axes[0] = {1, 0, 0}, axes[1] = {0, 1, 0}, axes[2] = {0, 0, 1};
      // Orthonormal, right-handed.
      axes[0] = glm::normalize(axes[0]);
      axes[1] = glm::normalize(axes[1] - axes[0] * glm::dot(axes[0], axes[1]));
      axes[2] = glm::cross(axes[0], axes[1]);
      for (std::uint32_t v : mem) {
        const glm::dvec3 n(normals[v]);
        int best = 5;  // -axes[2] … ordering below; zero normals: +axes[2]
        double bd = -2;
        for (int k = 0; k < 6; ++k) {
          const double d = (k < 3 ? 1.0 : -1.0) * glm::dot(n, axes[k % 3]);
          if (d > bd + 1e-12) bd = d, best = k;
        }
        if (glm::dot(n, n) == 0) best = 2;
        cluster[v] = static_cast<std::uint8_t>(best);
      }
      // Connected pieces of each direction.
      for (std::uint32_t v : mem) {
        if (vchart[v] != kNone) continue;
        const int k = cluster[v];
        ChartMap m;
        m.kind = region[v] == Region::Sheet ? Chart::Kind::Sheet : Chart::Kind::Joint;
        m.axis = (k < 3 ? 1.0 : -1.0) * axes[k % 3];
        m.b1 = axes[(k + 1) % 3];
        m.b2 = glm::cross(m.axis, m.b1);
        const auto id = static_cast<std::uint32_t>(maps.size());
        maps.push_back(m);
        vchart[v] = id;
        stack = {v};
        while (!stack.empty()) {
          const std::uint32_t a = stack.back();
          stack.pop_back();
          for (std::uint32_t q = adj_start[a]; q < adj_start[a + 1]; ++q) {
            const std::uint32_t b = adj[q];
            if (vchart[b] == kNone && comp[b] == ci && cluster[b] == k) vchart[b] = id, stack.push_back(b);
          }
        }
      }
    }
  };

  // Turns every planar chart's (b1, b2) to the principal axes of its vertices' projections, so
  // its rectangle (the bounding box) wastes less of the atlas on elongated, diagonal pieces.
  const auto align_planar_charts = [&] {
    std::vector<std::array<double, 6>> acc(maps.size(), {0, 0, 0, 0, 0, 0});  // n, x, y, xx, yy, xy
    for (std::size_t v = 0; v < V; ++v) {
      const ChartMap& m = maps[vchart[v]];
      if (m.kind == Chart::Kind::Bone || m.cap) continue;
      const glm::dvec3 p(mesh.positions[v]);
      const double x = glm::dot(p, m.b1), y = glm::dot(p, m.b2);
      auto& a = acc[vchart[v]];
      a[0] += 1, a[1] += x, a[2] += y, a[3] += x * x, a[4] += y * y, a[5] += x * y;
    }
    for (std::size_t c = 0; c < maps.size(); ++c) {
      const auto& a = acc[c];
      if (a[0] < 3) continue;
      const double mx = a[1] / a[0], my = a[2] / a[0];
      const double cxx = a[3] / a[0] - mx * mx, cyy = a[4] / a[0] - my * my, cxy = a[5] / a[0] - mx * my;
      const double angle = 0.5 * std::atan2(2 * cxy, cxx - cyy);
      ChartMap& m = maps[c];
      const glm::dvec3 b1 = std::cos(angle) * m.b1 + std::sin(angle) * m.b2;
      m.b1 = glm::normalize(b1);
      m.b2 = glm::cross(m.axis, m.b1);
    }
  };

  // Per chart, where filled: each vertex's coordinates in the chart's conformal map (5c), which
  // replaces the chart's projection; a vertex outside the map's domain has none (NaN).
  std::vector<std::unordered_map<std::uint32_t, glm::dvec2>> conformal;
  const auto vertex_local = [&](std::uint32_t c, std::uint32_t v) {
    if (c < conformal.size() && !conformal[c].empty()) {
      const auto it = conformal[c].find(v);
      return it != conformal[c].end() ? it->second : glm::dvec2(std::numeric_limits<double>::quiet_NaN());
    }
    return local_coords(maps[c], B, glm::dvec3(mesh.positions[v]));
  };
  // Local corners of face f in chart c (model units), wrapping charts unwrapped toward the
  // first corner that belongs to c (or corner 0).
  const auto face_local = [&](std::size_t f, std::uint32_t c, glm::dvec2 (&uv)[3]) {
    const Triangle& t = mesh.triangles[f];
    if (c < conformal.size() && !conformal[c].empty()) {
      for (int k = 0; k < 3; ++k) uv[k] = vertex_local(c, t[k]);
      return;
    }
    int ref = 0;
    for (int k = 0; k < 3; ++k) {
      uv[k] = local_coords(maps[c], B, glm::dvec3(mesh.positions[t[k]]));
      if (vchart[t[k]] == c && vchart[t[ref]] != c) ref = k;
    }
    if (maps[c].kind == Chart::Kind::Bone && maps[c].wraps && maps[c].width > 0) {
      unwrap(uv, ref, maps[c].width);
      // Keep the triangle overlapping [0, width): shift it whole when it fell outside.
      const double w = maps[c].width;
      const double xmax = std::max({uv[0].x, uv[1].x, uv[2].x}), xmin = std::min({uv[0].x, uv[1].x, uv[2].x});
      const double shift = xmax <= 0 ? w : (xmin >= w ? -w : 0.0);
      for (glm::dvec2& q : uv) q.x += shift;
    }
  };
  const auto face_charts = [&](std::size_t f, std::uint32_t (&cs)[3]) {
    int n = 0;
    for (std::uint32_t v : mesh.triangles[f]) {
      const std::uint32_t c = vchart[v];
      if (std::find(cs, cs + n, c) == cs + n) cs[n++] = c;
    }
    return n;
  };

  // The mean edge (one per face), the cell of the overlap tests' grids.
  double mean_edge = 0;
  for (const Triangle& t : mesh.triangles)
    mean_edge += glm::length(glm::dvec3(mesh.positions[t[1]]) - glm::dvec3(mesh.positions[t[0]]));
  mean_edge /= static_cast<double>(std::max<std::size_t>(F, 1));

  // 4. Demote the vertices of stretched, flipped or overlapping triangles in bone and cap charts.
  for (int round = 0; round < 12; ++round) {
    build_charts();
    std::vector<std::uint8_t> demote(V, 0);
    bool any = false;
    // Each bone or cap chart's faces with two or three corners in it: their chart coordinates
    // and corners, for the overlap test below.
    std::vector<std::vector<std::array<glm::dvec2, 3>>> uvs(maps.size());
    std::vector<std::vector<Triangle>> corners(maps.size());
    for (std::size_t f = 0; f < F; ++f) {
      const Triangle& t = mesh.triangles[f];
      std::uint32_t cs[3];
      const int nc = face_charts(f, cs);
      for (int i = 0; i < nc; ++i) {
        const ChartMap& m = maps[cs[i]];
        if (m.kind != Chart::Kind::Bone && !m.cap) continue;
        glm::dvec2 uv[3];
        face_local(f, cs[i], uv);
        const glm::dvec3 p0(mesh.positions[t[0]]), p1(mesh.positions[t[1]]), p2(mesh.positions[t[2]]);
        const double model = std::max({glm::length(p1 - p0), glm::length(p2 - p1), glm::length(p0 - p2)});
        const double local = std::max({glm::length(uv[1] - uv[0]), glm::length(uv[2] - uv[1]), glm::length(uv[0] - uv[2])});
        int own = 0;
        for (std::uint32_t v : t) own += vchart[v] == cs[i];
        const double area3 = glm::length(glm::cross(p1 - p0, p2 - p0));
        const bool flipped = own >= 2 && area3 > 1e-12 * model * model && signed_area2(uv[0], uv[1], uv[2]) <= 0;
        if (local > options.max_stretch * model || flipped) {
          for (std::uint32_t v : t)
            if (vchart[v] == cs[i]) demote[v] = 1, any = true;
        }
        if (own >= 2) uvs[cs[i]].push_back({uv[0], uv[1], uv[2]}), corners[cs[i]].push_back(t);
      }
    }
    // Then where a bone or cap chart's map is not one-to-one: its faces (those with two or three
    // corners in it) that overlap one another there, such as a blade or a fin of a CAD part
    // mapped onto the same angles and arc lengths as the hub under it (rotor: 3.2 % of the
    // covered texels carried two parts of the surface, read back up to 0.17 off heat diffusion
    // at sigma 2 edges on a field of amplitude ~1).
    if (!any) {
      for (std::size_t c = 0; c < maps.size(); ++c) {
        if (uvs[c].empty()) continue;
        const double period = maps[c].kind == Chart::Kind::Bone && maps[c].wraps ? maps[c].width : 0.0;
        const std::vector<std::uint8_t> flag = overlapping_triangles(uvs[c], corners[c], period, mean_edge, 1e-3 * mean_edge);
        for (std::size_t i = 0; i < flag.size(); ++i)
          if (flag[i])
            for (std::uint32_t v : corners[c][i])
              if (vchart[v] == c) demote[v] = 1, any = true;
      }
    }
    if (!any) break;
    for (std::size_t v = 0; v < V; ++v)
      if (demote[v]) region[v] = Region::Joint, owner[v] = kNone;
    if (round == 11) build_charts();
  }

  // With an overlap band, a planar chart projects along the mean normal of its own faces (area
  // weighted) rather than along the principal direction it was split by: its band then reaches
  // equally far to every side before the projection folds (at 90° from the axis), where it would
  // stop early on the side the split direction leans away from. Kept only if none of the chart's
  // own faces flips under the new axis.
  if (options.overlap > 0) {
    std::vector<glm::dvec3> mean_n(maps.size(), glm::dvec3(0.0));
    for (const Triangle& t : mesh.triangles) {
      const std::uint32_t c = vchart[t[0]];
      if (vchart[t[1]] != c || vchart[t[2]] != c || maps[c].kind == Chart::Kind::Bone || maps[c].cap) continue;
      mean_n[c] += glm::cross(glm::dvec3(mesh.positions[t[1]]) - glm::dvec3(mesh.positions[t[0]]),
                              glm::dvec3(mesh.positions[t[2]]) - glm::dvec3(mesh.positions[t[0]]));
    }
    std::vector<std::uint8_t> keeps(maps.size(), 1);
    for (const Triangle& t : mesh.triangles) {
      const std::uint32_t c = vchart[t[0]];
      if (vchart[t[1]] != c || vchart[t[2]] != c || maps[c].kind == Chart::Kind::Bone || maps[c].cap) continue;
      const glm::dvec3 n = glm::cross(glm::dvec3(mesh.positions[t[1]]) - glm::dvec3(mesh.positions[t[0]]),
                                      glm::dvec3(mesh.positions[t[2]]) - glm::dvec3(mesh.positions[t[0]]));
      if (glm::dot(n, mean_n[c]) <= 0) keeps[c] = 0;
    }
    for (std::size_t c = 0; c < maps.size(); ++c) {
      const double len = glm::length(mean_n[c]);
      if (!keeps[c] || !(len > 0)) continue;
      ChartMap& m = maps[c];
      m.axis = mean_n[c] / len;
      m.b1 = any_perpendicular(m.axis);
      m.b2 = glm::cross(m.axis, m.b1);
    }
  }
  // With an overlap band, a planar chart becomes an azimuthal (stereographic) map (the end caps' map)
  // around the mean of its vertices' skeleton nodes, which lie inside the solid: a surface around
  // the skeleton is seen from there without folding until the far side, where an orthographic
  // projection folds at 90° from its axis, so the band reaches round a limb or a junction instead of
  // stopping at its silhouette (camel, sigma 3 edges: seam ratio 7.3 -> 3.9). Kept for a chart only
  // if none of its own faces flips or stretches past max_stretch under it.
  if (options.overlap > 0) {
    std::vector<glm::dvec3> org(maps.size(), glm::dvec3(0.0)), cen(maps.size(), glm::dvec3(0.0));
    std::vector<double> cnt(maps.size(), 0.0);
    for (std::size_t v = 0; v < V; ++v) {
      const std::uint32_t c = vchart[v];
      if (maps[c].kind == Chart::Kind::Bone || maps[c].cap) continue;
      org[c] += glm::dvec3(skel.nodes[vnode[v]].position);
      cen[c] += glm::dvec3(mesh.positions[v]);
      cnt[c] += 1;
    }
    std::vector<ChartMap> old = maps;
    std::vector<std::uint8_t> cand(maps.size(), 0);
    for (std::size_t c = 0; c < maps.size(); ++c) {
      if (!(cnt[c] > 0)) continue;
      const glm::dvec3 o = org[c] / cnt[c], ce = cen[c] / cnt[c];
      const double d = glm::length(ce - o);
      if (!(d > 0)) continue;
      ChartMap& m = maps[c];
      m.cap = true;
      m.origin = o;
      m.axis = (ce - o) / d;
      m.b1 = any_perpendicular(m.axis);
      m.b2 = glm::cross(m.axis, m.b1);
      cand[c] = 1;
    }
    std::vector<double> sum(maps.size(), 0.0);
    for (std::size_t v = 0; v < V; ++v)
      if (cand[vchart[v]]) sum[vchart[v]] += glm::length(glm::dvec3(mesh.positions[v]) - maps[vchart[v]].origin);
    for (std::size_t c = 0; c < maps.size(); ++c)
      if (cand[c]) maps[c].cap_radius = sum[c] / cnt[c];
    // The test of the demotion rounds: every face touching the chart unstretched, those with two
    // or three corners in it unflipped.
    std::vector<std::uint8_t> bad(maps.size(), 0);
    for (std::size_t f = 0; f < F; ++f) {
      const Triangle& t = mesh.triangles[f];
      std::uint32_t cs[3];
      const int nc = face_charts(f, cs);
      for (int i = 0; i < nc; ++i) {
        const std::uint32_t c = cs[i];
        if (!cand[c]) continue;
        glm::dvec2 uv[3];
        face_local(f, c, uv);
        const glm::dvec3 p0(mesh.positions[t[0]]), p1(mesh.positions[t[1]]), p2(mesh.positions[t[2]]);
        const double model = std::max({glm::length(p1 - p0), glm::length(p2 - p1), glm::length(p0 - p2)});
        const double loc = std::max({glm::length(uv[1] - uv[0]), glm::length(uv[2] - uv[1]), glm::length(uv[0] - uv[2])});
        int own = 0;
        for (std::uint32_t v : t) own += vchart[v] == c;
        if ((own >= 2 && signed_area2(uv[0], uv[1], uv[2]) <= 0) || loc > options.max_stretch * model) bad[c] = 1;
      }
    }
    for (std::size_t c = 0; c < maps.size(); ++c)
      if (bad[c]) maps[c] = old[c];
  }
  align_planar_charts();

  // 5. Atlas triangles in local coordinates; chart extents.
  struct LocalTri {
    std::uint32_t chart, face;
    glm::dvec2 uv[3];
  };
  std::vector<LocalTri> local;
  local.reserve(F + F / 4);
  for (std::size_t f = 0; f < F; ++f) {
    std::uint32_t cs[3];
    const int nc = face_charts(f, cs);
    for (int i = 0; i < nc; ++i) {
      LocalTri lt{cs[i], static_cast<std::uint32_t>(f), {}};
      face_local(f, cs[i], lt.uv);
      local.push_back(lt);
      ChartMap& m = maps[cs[i]];
      for (const glm::dvec2& q : lt.uv) m.lo = glm::min(m.lo, q), m.hi = glm::max(m.hi, q);
    }
  }
  // Blended read-back (StmOptions::blend): per chart, the vertices it covers and their weights.
  struct BandSample {
    std::uint32_t vertex, chart;
    double weight;
  };
  std::vector<BandSample> band_samples;
  std::vector<double> own_weight;
  const bool blend = options.blend && options.overlap > 0;
  const double blend_reach = kBlendShare * options.overlap;
  // Smoothstep over [0, blend_reach] of the distance to where a chart's coverage ends.
  const auto blend_weight = [&](double d) {
    const double t = std::clamp(d / blend_reach, 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
  };
  if (blend) own_weight.assign(V, 1.0);
  // Per vertex, with a band: how far around it the chart that covers it deepest reaches, along the
  // surface, up to the band (AtlasMapping::vertex_reach).
  std::vector<float> reach(options.overlap > 0 ? V : 0, 0.0f);
  // 5b. Overlap bands (StmOptions::overlap): per chart, the faces within `overlap` of its own
  // vertices along the surface (Dijkstra over the edges, from all its vertices at once), grown
  // face by face out of the faces it already holds, through faces its map keeps oriented as the
  // chart's own faces are and does not stretch: where the map folds (a planar chart reaching
  // around a limb, a bone chart past its end) the band stops.
  if (options.overlap > 0) {
    const Adjacency faces_around = vertex_faces(mesh);
    const std::vector<std::uint32_t>& vf_start = faces_around.offsets;
    const std::vector<std::uint32_t>& vf = faces_around.indices;
    std::vector<std::vector<std::uint32_t>> chart_vertices(maps.size());
    for (std::size_t v = 0; v < V; ++v) chart_vertices[vchart[v]].push_back(static_cast<std::uint32_t>(v));
    std::vector<double> dist(V, std::numeric_limits<double>::infinity());
    std::vector<std::uint32_t> reached, faces;
    std::vector<std::uint8_t> face_state(F, 0);  // 1: in the chart, 2: rejected
    using Item = std::pair<double, std::uint32_t>;
    std::vector<Item> heap;
    // Per chart: covered vertices; cover = inf (not covered), -1 (covered, coverage farther than
    // the blend), or the distance to the coverage's end.
    std::vector<std::uint32_t> covered;
    std::vector<double> cover(V, std::numeric_limits<double>::infinity());
    std::vector<double> dsum(blend ? V : 0, 0.0), dcnt(blend ? V : 0, 0.0);
    const double distortion_k = kBlendDistortion;
    const std::size_t own_triangles = local.size();
    std::vector<std::vector<std::uint32_t>> held(maps.size());  // faces each chart holds already
    std::vector<std::vector<std::uint32_t>> held_local(maps.size());  // their indices in `local`
    for (std::size_t i = 0; i < own_triangles; ++i)
      held[local[i].chart].push_back(local[i].face), held_local[local[i].chart].push_back(static_cast<std::uint32_t>(i));
    if (options.conformal) conformal.assign(maps.size(), {});
    // A band must not fold over its own chart either: a band face whose chart triangle overlaps
    // one the chart already holds (a planar map reaching round a limb onto its own far side, an
    // azimuthal map past the antipode, a bone's cylindrical map round a bend) stops the band
    // there like a flip does, so no texel carries two parts of the surface for the blur to mix
    // (elephant, sigma 5 edges: texels covered twice 7.1 % -> 0.35 %, RMS against heat
    // 0.0368 -> 0.0331). The chart's triangles go in a uniform grid of its local coordinates,
    // cell = the mean edge length; triangles sharing a vertex may touch.
    // Cell -> the last of its entries; entries chain (next entry, triangle) without a vector per cell.
    std::unordered_map<std::uint64_t, std::uint32_t> grid;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> grid_entries;
    constexpr std::uint32_t kEnd = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::array<glm::dvec2, 3>> grid_tris;
    std::vector<std::uint32_t> grid_faces;
    const auto cell_key = [&](long ix, long iy) {
      return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(ix)) << 32) | static_cast<std::uint32_t>(iy);
    };
    const auto cells_of = [&](const glm::dvec2 (&uv)[3], auto&& fn) {
      glm::dvec2 lo = glm::min(glm::min(uv[0], uv[1]), uv[2]), hi = glm::max(glm::max(uv[0], uv[1]), uv[2]);
      const long x0 = static_cast<long>(std::floor(lo.x / mean_edge)), x1 = static_cast<long>(std::floor(hi.x / mean_edge));
      const long y0 = static_cast<long>(std::floor(lo.y / mean_edge)), y1 = static_cast<long>(std::floor(hi.y / mean_edge));
      if ((x1 - x0 + 1) * (y1 - y0 + 1) > 4096) return;
      for (long x = x0; x <= x1; ++x)
        for (long y = y0; y <= y1; ++y) fn(cell_key(x, y));
    };
    const auto grid_clear = [&] {
      grid.clear();
      grid_entries.clear();
      grid_tris.clear();
      grid_faces.clear();
    };
    const auto grid_insert = [&](std::uint32_t f, const glm::dvec2 (&uv)[3]) {
      const auto id = static_cast<std::uint32_t>(grid_tris.size());
      grid_tris.push_back({uv[0], uv[1], uv[2]});
      grid_faces.push_back(f);
      cells_of(uv, [&](std::uint64_t k) {
        const auto [it, fresh] = grid.try_emplace(k, kEnd);
        grid_entries.push_back({it->second, id});
        it->second = static_cast<std::uint32_t>(grid_entries.size() - 1);
        (void)fresh;
      });
    };
    const auto grid_overlaps = [&](std::uint32_t f, const glm::dvec2 (&uv)[3]) {
      bool hit = false;
      const Triangle& tf = mesh.triangles[f];
      cells_of(uv, [&](std::uint64_t k) {
        if (hit) return;
        const auto it = grid.find(k);
        if (it == grid.end()) return;
        for (std::uint32_t e = it->second; e != kEnd; e = grid_entries[e].first) {
          const std::uint32_t id = grid_entries[e].second;
          const Triangle& tg = mesh.triangles[grid_faces[id]];
          bool shares = false;
          for (std::uint32_t a : tf)
            for (std::uint32_t b : tg) shares = shares || a == b;
          if (shares) continue;
          const glm::dvec2 other[3] = {grid_tris[id][0], grid_tris[id][1], grid_tris[id][2]};
          if (triangles_overlap(uv, other, 1e-3 * mean_edge)) {
            hit = true;
            return;
          }
        }
      });
      return hit;
    };
    // The least squares conformal map of chart c over `domain` (faces), into conformal[c]: each
    // face's residual Σ_j W_j ζ_j / √(2 area) (W_j = z_{j+2} - z_{j+1} in the face's own plane,
    // ζ = u + i v), zero exactly for a similarity; the chart's two vertices farthest apart in its
    // projection pinned at their distance. A band face that turns against the chart's own faces,
    // is squashed (σ1/σ2 > max_stretch), stretched past max_stretch, overlaps a face nearer the
    // chart or is not joined to the chart's faces across edges leaves the domain (into `trimmed`)
    // and the map is solved again, up to 4 times; false (nothing kept) when one of the chart's own
    // faces does one of the first four, or the solve fails. `seeded_by_unfolding`: the band was
    // laid out by unfolding (`unfolded`), which then says how its faces are oriented.
    std::vector<std::int32_t> lscm_index(V, -1);
    // Band growth by unfolding (below): per vertex, its place in the chart's plane, and which
    // vertices have one.
    std::vector<glm::dvec2> unfolded(V);
    std::vector<std::uint8_t> has_unfolded(V, 0);
    std::vector<std::uint32_t> unfolded_touched;
    // A band's reach round its chart's vertices (below): per vertex, -1 where covered and not yet
    // reached, else the distance to where the coverage ends; infinity where not covered.
    std::vector<double> depth(V, std::numeric_limits<double>::infinity());
    std::vector<std::uint32_t> depth_touched;
    const auto conformal_map = [&](std::uint32_t c, std::vector<std::uint32_t> domain, double orientation,
                                   bool seeded_by_unfolding, std::vector<std::uint32_t>& trimmed) {
      std::uint32_t pa = kNone, pb = kNone;
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (std::uint32_t v : chart_vertices[c]) {
        const double x = local_coords(maps[c], B, glm::dvec3(mesh.positions[v])).x;
        if (x < lo) lo = x, pa = v;
        if (x > hi) hi = x, pb = v;
      }
      const double span = pa == kNone || pb == kNone ? 0.0 : glm::length(glm::dvec3(mesh.positions[pb]) - glm::dvec3(mesh.positions[pa]));
      if (!(span > 0)) return false;
      // Whether each domain face is oriented like the chart's own faces in the projection: a face
      // touching the chart that the projection already flipped has no say below.
      std::vector<std::uint8_t> says(domain.size());
      // With an unfolded band, its faces' say comes from their unfolded places.
      for (std::size_t i = 0; i < domain.size(); ++i) {
        const Triangle& t = mesh.triangles[domain[i]];
        glm::dvec2 pr[3];
        bool unf = seeded_by_unfolding;
        for (int k = 0; k < 3; ++k) unf = unf && has_unfolded[t[k]];
        for (int k = 0; k < 3; ++k) pr[k] = unf ? unfolded[t[k]] : local_coords(maps[c], B, glm::dvec3(mesh.positions[t[k]]));
        says[i] = orientation * signed_area2(pr[0], pr[1], pr[2]) > 0;
      }
      std::vector<std::uint32_t> verts, bad;
      const auto cleanup = [&] {
        for (std::uint32_t v : verts) lscm_index[v] = -1;
        verts.clear();
      };
      const auto own_face = [&](const Triangle& t) { return vchart[t[0]] == c || vchart[t[1]] == c || vchart[t[2]] == c; };
      // Edge k of a triangle (corners k, k + 1), whichever way round.
      const auto edge_key = [](const Triangle& t, int k) {
        const std::uint32_t a = std::min(t[k], t[(k + 1) % 3]), b = std::max(t[k], t[(k + 1) % 3]);
        return (static_cast<std::uint64_t>(a) << 32) | b;
      };
      std::vector<std::pair<std::uint64_t, std::uint32_t>> edges;
      std::vector<std::uint8_t> joined;
      std::vector<std::uint32_t> reach_queue;
      for (int round = 0; round < 4; ++round) {
        cleanup();
        // An unfolded band keeps only faces joined to the chart's own faces across edges inside
        // the domain: a piece that hangs on by a corner, or that trimming cut off, has no unique
        // conformal map.
        edges.clear();
        for (std::size_t i = 0; i < domain.size(); ++i) {
          const Triangle& t = mesh.triangles[domain[i]];
          for (int k = 0; k < 3; ++k) edges.push_back({edge_key(t, k), static_cast<std::uint32_t>(i)});
        }
        std::sort(edges.begin(), edges.end());
        joined.assign(domain.size(), 0);
        reach_queue.clear();
        for (std::size_t i = 0; i < domain.size(); ++i)
          if (own_face(mesh.triangles[domain[i]])) joined[i] = 1, reach_queue.push_back(static_cast<std::uint32_t>(i));
        for (std::size_t q = 0; q < reach_queue.size(); ++q) {
          const Triangle& t = mesh.triangles[domain[reach_queue[q]]];
          for (int k = 0; k < 3; ++k) {
            const std::uint64_t key = edge_key(t, k);
            for (auto it = std::lower_bound(edges.begin(), edges.end(), std::make_pair(key, std::uint32_t{0}));
                 it != edges.end() && it->first == key; ++it)
              if (!joined[it->second]) joined[it->second] = 1, reach_queue.push_back(it->second);
          }
        }
        if (seeded_by_unfolding && reach_queue.size() < domain.size()) {
          std::size_t kept = 0;
          for (std::size_t i = 0; i < domain.size(); ++i)
            if (joined[i]) domain[kept] = domain[i], says[kept++] = says[i];
            else trimmed.push_back(domain[i]);
          domain.resize(kept);
          says.resize(kept);
        }
        for (std::uint32_t f : domain)
          for (std::uint32_t v : mesh.triangles[f])
            if (lscm_index[v] < 0) lscm_index[v] = static_cast<std::int32_t>(verts.size()), verts.push_back(v);
        const auto n = static_cast<std::int32_t>(verts.size());
        // Both pins must be corners of the domain (a vertex no face uses is not).
        if (n < 3 || lscm_index[pa] < 0 || lscm_index[pb] < 0) return cleanup(), false;
        const std::int32_t ia = lscm_index[pa], ib = lscm_index[pb];
        const auto column = [&](std::int32_t i) { return i - (i > ia ? 1 : 0) - (i > ib ? 1 : 0); };
        std::vector<Eigen::Triplet<double>> entries;
        std::vector<double> rhs_rows;
        std::int32_t row = 0;
        for (std::uint32_t f : domain) {
          const Triangle& t = mesh.triangles[f];
          const std::optional<PlaneTriangle> pt = in_own_plane(
              glm::dvec3(mesh.positions[t[0]]), glm::dvec3(mesh.positions[t[1]]), glm::dvec3(mesh.positions[t[2]]));
          if (!pt || !(pt->twice_area > 1e-14 * pt->l1 * pt->l1)) continue;
          const glm::dvec2 q[3] = {{0, 0}, {pt->l1, 0}, {pt->ex, pt->ey}};
          const double w = 1.0 / std::sqrt(pt->twice_area);
          double re = 0, im = 0;
          for (int j = 0; j < 3; ++j) {
            const glm::dvec2 wj = q[(j + 2) % 3] - q[(j + 1) % 3];
            const std::int32_t i = lscm_index[t[j]];
            if (i == ia || i == ib) {  // pinned: (0, 0) and (span, 0)
              const double px = i == ia ? 0.0 : span;
              re += wj.x * px, im += wj.y * px;
              continue;
            }
            const std::int32_t col = column(i);
            entries.emplace_back(row, 2 * col, w * wj.x);
            entries.emplace_back(row, 2 * col + 1, -w * wj.y);
            entries.emplace_back(row + 1, 2 * col, w * wj.y);
            entries.emplace_back(row + 1, 2 * col + 1, w * wj.x);
          }
          rhs_rows.push_back(-w * re);
          rhs_rows.push_back(-w * im);
          row += 2;
        }
        if (row == 0) return cleanup(), false;
        Eigen::SparseMatrix<double> A(row, 2 * (n - 2));
        A.setFromTriplets(entries.begin(), entries.end());
        const Eigen::Map<const Eigen::VectorXd> rhs(rhs_rows.data(), row);
        const Eigen::SparseMatrix<double> normal = A.transpose() * A;
        Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
        if (solver.info() != Eigen::Success) return cleanup(), false;
        const Eigen::VectorXd x = solver.solve(A.transpose() * rhs);
        if (solver.info() != Eigen::Success || !x.allFinite()) return cleanup(), false;
        const auto coord = [&](std::uint32_t v) {
          const std::int32_t i = lscm_index[v];
          return i == ia ? glm::dvec2(0.0) : i == ib ? glm::dvec2(span, 0.0) : glm::dvec2(x[2 * column(i)], x[2 * column(i) + 1]);
        };
        // The orientation of the chart's own faces (up to a mirror, the projection's), and the
        // faces that turn against it, are squashed or stretched.
        double votes = 0;
        for (std::size_t i = 0; i < domain.size(); ++i) {
          const Triangle& t = mesh.triangles[domain[i]];
          if (!own_face(t) || !says[i]) continue;
          votes += signed_area2(coord(t[0]), coord(t[1]), coord(t[2])) > 0 ? 1 : -1;
        }
        const double flip = votes >= 0 ? 1.0 : -1.0;
        bad.clear();
        bool own_bad = false;
        for (std::size_t i = 0; i < domain.size(); ++i) {
          const std::uint32_t f = domain[i];
          const Triangle& t = mesh.triangles[f];
          if (!says[i]) continue;
          const glm::dvec2 uv[3] = {coord(t[0]), coord(t[1]), coord(t[2])};
          bool fine = flip * signed_area2(uv[0], uv[1], uv[2]) > 0;
          const auto sv = face_map_singular_values(glm::dvec3(mesh.positions[t[0]]), glm::dvec3(mesh.positions[t[1]]),
                                                   glm::dvec3(mesh.positions[t[2]]), uv);
          // Shape kept, no stretch past max_stretch in model units (the projections' test: the
          // atlas's scale is set by the largest chart, one map blown up costs every chart), and
          // no compression past it either: a conformal map may shrink part of a chart into a few
          // texels, where the blur has nothing to work with (CGAL's bones: 3.08x k-ring's error
          // against heat at 2 edges, 0.91x with this bound).
          if (fine && sv)
            fine = sv->second * options.max_stretch >= sv->first && sv->first <= options.max_stretch &&
                   sv->second * options.max_stretch >= 1.0;
          if (fine) continue;
          if (own_face(t)) own_bad = true;
          bad.push_back(f);
        }
        if (own_bad) return cleanup(), false;
        // Nor folded over itself (the band's overlap test, on the new coordinates). In an unfolded
        // band, of two faces that overlap, the one farther out (later in the domain) leaves it.
        if (bad.empty()) {
          grid_clear();
          for (std::uint32_t f : domain) {
            const Triangle& t = mesh.triangles[f];
            const glm::dvec2 uv[3] = {coord(t[0]), coord(t[1]), coord(t[2])};
            if (grid_overlaps(f, uv)) {
              if (!seeded_by_unfolding || own_face(t)) return cleanup(), false;
              bad.push_back(f);
              continue;
            }
            grid_insert(f, uv);
          }
        }
        if (!bad.empty()) {
          if (round == 3) return cleanup(), false;
          std::sort(bad.begin(), bad.end());
          std::size_t kept = 0;
          for (std::size_t i = 0; i < domain.size(); ++i)
            if (!std::binary_search(bad.begin(), bad.end(), domain[i])) domain[kept] = domain[i], says[kept++] = says[i];
          domain.resize(kept);
          says.resize(kept);
          trimmed.insert(trimmed.end(), bad.begin(), bad.end());
          continue;
        }
        // Mirrored to the projection's orientation, so the band's orientation test still holds.
        auto& table = conformal[c];
        table.reserve(verts.size());
        for (std::uint32_t v : verts) {
          glm::dvec2 q = coord(v);
          if (flip * orientation < 0) q.y = -q.y;
          table[v] = q;
        }
        cleanup();
        return true;
      }
      return cleanup(), false;
    };
    for (std::uint32_t c = 0; c < maps.size(); ++c) {
      // A wrapping (bone) chart's x is periodic: each triangle goes in the grid at its place and
      // one period to either side, so a band face that lands on the chart's own surface modulo
      // the period is found too (a bent tube's band reaching round the bend's inner side onto the
      // bone's own faces: knot, sigma 5 edges, 54 of 2080 vertices read back up to 0.6 off a field
      // of amplitude ~1 with no blur at all, before this check covered wrapping charts).
      const double period = maps[c].kind == Chart::Kind::Bone && maps[c].wraps && maps[c].width > 0 ? maps[c].width : 0.0;
      const auto insert_wrapped = [&](std::uint32_t f, const glm::dvec2 (&uv)[3]) {
        grid_insert(f, uv);
        if (period <= 0) return;
        for (const double shift : {-period, period}) {
          const glm::dvec2 moved[3] = {uv[0] + glm::dvec2(shift, 0.0), uv[1] + glm::dvec2(shift, 0.0), uv[2] + glm::dvec2(shift, 0.0)};
          grid_insert(f, moved);
        }
      };
      // The grid holds the faces the chart holds already (and what its band adds).
      const auto grid_of_held = [&] {
        grid_clear();
        for (std::uint32_t f : held[c]) {
          glm::dvec2 uv[3];
          face_local(f, c, uv);
          insert_wrapped(f, uv);
        }
      };
      grid_of_held();
      // Distances along the surface from the chart's vertices, up to the band.
      heap.clear();
      for (std::uint32_t v : chart_vertices[c]) dist[v] = 0, reached.push_back(v), heap.push_back({0.0, v});
      std::make_heap(heap.begin(), heap.end(), std::greater<>());
      while (!heap.empty()) {
        std::pop_heap(heap.begin(), heap.end(), std::greater<>());
        const auto [d, a] = heap.back();
        heap.pop_back();
        if (d > dist[a]) continue;
        for (std::uint32_t k = adj_start[a]; k < adj_start[a + 1]; ++k) {
          const std::uint32_t b = adj[k];
          const double nd = d + glm::length(glm::dvec3(mesh.positions[a]) - glm::dvec3(mesh.positions[b]));
          if (nd > options.overlap || nd >= dist[b]) continue;
          if (!std::isfinite(dist[b])) reached.push_back(b);
          dist[b] = nd;
          heap.push_back({nd, b});
          std::push_heap(heap.begin(), heap.end(), std::greater<>());
        }
      }
      // The chart's orientation: the sign most of its own faces have in its map.
      double orientation = 0;
      for (std::uint32_t f : held[c]) {
        const Triangle& t = mesh.triangles[f];
        if (vchart[t[0]] != c || vchart[t[1]] != c || vchart[t[2]] != c) continue;
        glm::dvec2 uv[3];
        face_local(f, c, uv);
        orientation += signed_area2(uv[0], uv[1], uv[2]) > 0 ? 1 : -1;
      }
      const double sign = orientation >= 0 ? 1.0 : -1.0;
      // Grow from the faces the chart holds through vertex-adjacent faces in reach (`radius`).
      // `unfold` (charts that take a conformal map): a corner keeps the place it got first, and
      // a face the projection does not fit is unfolded, laid into the plane in its own shape (a
      // similarity) onto an edge whose ends are placed already, so the band goes round a sharp
      // edge or onto a side the projection sees edge-on, where heat flow goes too (CAD parts,
      // whose planar charts meet at sharp edges: every band stopped there, and the blur saw each
      // side alone). A face with fewer than two corners placed that the projection does not fit
      // waits for a neighbour to place a second.
      const std::size_t band_begin = local.size();
      const glm::dvec2 lo_before = maps[c].lo, hi_before = maps[c].hi;
      // Returns how many faces were unfolded.
      const auto grow = [&](bool unfold, double radius) {
        std::size_t unfolded_faces = 0;
        faces = held[c];
        for (std::uint32_t f : faces) face_state[f] = 1;
        if (unfold)
          for (std::uint32_t f : held[c]) {
            glm::dvec2 uv[3];
            face_local(f, c, uv);
            for (int k = 0; k < 3; ++k) {
              const std::uint32_t v = mesh.triangles[f][k];
              if (has_unfolded[v]) continue;
              has_unfolded[v] = 1, unfolded[v] = uv[k];
              unfolded_touched.push_back(v);
            }
          }
        for (std::size_t i = 0; i < faces.size(); ++i)
          for (std::uint32_t v : mesh.triangles[faces[i]])
            for (std::uint32_t k = vf_start[v]; k < vf_start[v + 1]; ++k) {
              const std::uint32_t g = vf[k];
              if (face_state[g]) continue;
              const Triangle& t = mesh.triangles[g];
              if (!(std::min({dist[t[0]], dist[t[1]], dist[t[2]]}) <= radius)) continue;
              LocalTri lt{c, g, {}};
              const glm::dvec3 p0(mesh.positions[t[0]]), p1(mesh.positions[t[1]]), p2(mesh.positions[t[2]]);
              const double model = std::max({glm::length(p1 - p0), glm::length(p2 - p1), glm::length(p0 - p2)});
              // Kept where the chart's map keeps the face oriented as its own faces, unstretched,
              // and off the faces it holds already.
              const auto fits = [&](const glm::dvec2 (&uv)[3]) {
                const double loc = std::max({glm::length(uv[1] - uv[0]), glm::length(uv[2] - uv[1]), glm::length(uv[0] - uv[2])});
                return sign * signed_area2(uv[0], uv[1], uv[2]) > 0 && loc <= options.max_stretch * model && !grid_overlaps(g, uv);
              };
              face_local(g, c, lt.uv);
              bool ok;
              if (!unfold) {
                ok = fits(lt.uv);
              } else {
                // Corners placed already keep their place; the others take the projection's.
                int placed = 0, fresh = -1;
                for (int j = 0; j < 3; ++j)
                  if (has_unfolded[t[j]]) lt.uv[j] = unfolded[t[j]], ++placed;
                  else fresh = j;
                ok = fits(lt.uv);
                if (!ok && placed == 2) {
                  // Where the projection does not fit, the face is unfolded: laid in its own
                  // shape (a similarity) onto its placed edge (a, b), on the chart's side.
                  const int ia = (fresh + 1) % 3, ib = (fresh + 2) % 3;
                  const std::optional<PlaneTriangle> pt = in_own_plane(
                      glm::dvec3(mesh.positions[t[ia]]), glm::dvec3(mesh.positions[t[ib]]), glm::dvec3(mesh.positions[t[fresh]]));
                  const glm::dvec2 A = lt.uv[ia], Bq = lt.uv[ib];
                  const double len = glm::length(Bq - A);
                  if (pt && len > 0) {
                    const glm::dvec2 dir = (Bq - A) / len, perp(-dir.y, dir.x);
                    const double scale = len / pt->l1;
                    const glm::dvec2 along = A + scale * pt->ex * dir;
                    const glm::dvec2 x1 = along + scale * pt->ey * perp, x2 = along - scale * pt->ey * perp;
                    // (a, b, x) is t's order rotated, so its sign is the face's.
                    lt.uv[fresh] = sign * signed_area2(A, Bq, x1) > 0 ? x1 : x2;
                    ok = fits(lt.uv);
                    unfolded_faces += ok;
                  }
                }
                // Not yet: once a neighbour places a second corner, the face may unfold.
                if (!ok && placed < 2) continue;
                if (ok)
                  for (int j = 0; j < 3; ++j)
                    if (!has_unfolded[t[j]]) {
                      has_unfolded[t[j]] = 1, unfolded[t[j]] = lt.uv[j];
                      unfolded_touched.push_back(t[j]);
                    }
              }
              if (ok) insert_wrapped(g, lt.uv);
              face_state[g] = ok ? 1 : 2;
              faces.push_back(g);
              if (!ok) continue;
              local.push_back(lt);
              ChartMap& m = maps[c];
              for (const glm::dvec2& q : lt.uv) m.lo = glm::min(m.lo, q), m.hi = glm::max(m.hi, q);
            }
        return unfolded_faces;
      };
      // 5c. A joint or sheet chart's projection (orthographic, or central onto the sphere of
      // directions) foreshortens every face it sees obliquely, along the direction the face is
      // tilted in, which is not an atlas axis: the blur's per-axis widths cannot follow that, and
      // the map's Laplace-Beltrami operator gains a drift term that no blur carries. A conformal
      // map's is λ⁻² Δ, what the stretch-compensated blur does. So the faces the chart now holds
      // (its own and its band's, embedded in the plane without folds) take a least squares
      // conformal map (Lévy et al. 2002), kept where every one of them keeps its orientation and
      // its shape (σ1 / σ2 ≤ max_stretch).
      // The unfolded band (to the band's width, or where its map fails, half or a quarter of it)
      // and the band grown in the projection alone are both mapped, and the chart keeps the one
      // that reaches farther round its own vertices: the sum over them of the
      // distance along the surface to where the band's coverage ends, up to the band's width
      // (what a blur centred on them can use). Unfolding reaches round sharp edges, but where the
      // chart is small against its band (the band reaches round a small part), the conformal map
      // of the unfolded band trims more than the projection stops at (CGAL's pipe). Where the
      // projection's conformal map fails, its band stays in the projection, as before unfolding.
      const bool conformal_chart = options.conformal && maps[c].kind != Chart::Kind::Bone;
      const auto undo = [&] {
        for (std::uint32_t f : faces) face_state[f] = 0;
        local.resize(band_begin);
        maps[c].lo = lo_before, maps[c].hi = hi_before;
        conformal[c].clear();
        for (std::uint32_t i : held_local[c]) face_local(local[i].face, c, local[i].uv);
        grid_of_held();
      };
      // Grows the band and maps it; the faces the map keeps (0: it failed).
      // Returns kNothingUnfolded, without a map, when an unfolded band needed no unfolding (the
      // projection's band is the same).
      constexpr std::size_t kNothingUnfolded = std::numeric_limits<std::size_t>::max();
      const auto attempt = [&](bool unfold, double radius) -> std::size_t {
        if (grow(unfold, radius) == 0 && unfold) {
          for (std::uint32_t v : unfolded_touched) has_unfolded[v] = 0;
          unfolded_touched.clear();
          return kNothingUnfolded;
        }
        std::vector<std::uint32_t> domain_faces;
        for (std::uint32_t f : faces)
          if (face_state[f] == 1) domain_faces.push_back(f);
        std::vector<std::uint32_t> trimmed;
        const bool mapped = conformal_map(c, domain_faces, sign, unfold, trimmed);
        for (std::uint32_t v : unfolded_touched) has_unfolded[v] = 0;
        unfolded_touched.clear();
        if (!mapped) return unfold ? 0 : domain_faces.size();
        // The band faces the map could not keep leave the band.
        if (!trimmed.empty()) {
          for (std::uint32_t f : trimmed) face_state[f] = 2;
          local.erase(std::remove_if(local.begin() + static_cast<std::ptrdiff_t>(band_begin), local.end(),
                                     [&](const LocalTri& lt) { return face_state[lt.face] == 2; }),
                      local.end());
        }
        ChartMap& m = maps[c];
        m.lo = glm::dvec2(std::numeric_limits<double>::infinity());
        m.hi = -m.lo;
        const auto refresh = [&](LocalTri& lt) {
          face_local(lt.face, c, lt.uv);
          for (const glm::dvec2& q : lt.uv) m.lo = glm::min(m.lo, q), m.hi = glm::max(m.hi, q);
        };
        for (std::uint32_t i : held_local[c]) refresh(local[i]);
        for (std::size_t i = band_begin; i < local.size(); ++i) refresh(local[i]);
        return domain_faces.size() - trimmed.size();
      };
      // The vertices the band's faces cover (corners of faces in the chart), appended to
      // `touched`, with into `to_end` their distance along the surface to where the coverage ends
      // (covered vertices with a face around them the chart lacks), walked up to `limit`; -1
      // where farther. `to_end` is infinity everywhere else, and the caller resets what it touched.
      const auto coverage_depth = [&](std::vector<double>& to_end, std::vector<std::uint32_t>& touched, double limit) {
        for (std::uint32_t f : faces)
          if (face_state[f] == 1)
            for (std::uint32_t v : mesh.triangles[f])
              if (!std::isfinite(to_end[v])) to_end[v] = -1, touched.push_back(v);
        heap.clear();
        for (std::uint32_t v : touched) {
          bool inner = true;
          for (std::uint32_t k = vf_start[v]; k < vf_start[v + 1] && inner; ++k) inner = face_state[vf[k]] == 1;
          if (!inner) to_end[v] = 0, heap.push_back({0.0, v});
        }
        std::make_heap(heap.begin(), heap.end(), std::greater<>());
        while (!heap.empty()) {
          std::pop_heap(heap.begin(), heap.end(), std::greater<>());
          const auto [d, a] = heap.back();
          heap.pop_back();
          if (d > to_end[a] || d >= limit) continue;
          for (std::uint32_t k = adj_start[a]; k < adj_start[a + 1]; ++k) {
            const std::uint32_t b = adj[k];
            if (!std::isfinite(to_end[b])) continue;  // not covered
            const double nd = d + glm::length(glm::dvec3(mesh.positions[a]) - glm::dvec3(mesh.positions[b]));
            if (to_end[b] >= 0 && nd >= to_end[b]) continue;
            to_end[b] = nd;
            heap.push_back({nd, b});
            std::push_heap(heap.begin(), heap.end(), std::greater<>());
          }
        }
      };
      const auto band_reach = [&] {
        coverage_depth(depth, depth_touched, options.overlap);
        double sum = 0;
        for (std::uint32_t v : chart_vertices[c]) sum += depth[v] < 0 ? options.overlap : std::min(depth[v], options.overlap);
        for (std::uint32_t v : depth_touched) depth[v] = std::numeric_limits<double>::infinity();
        depth_touched.clear();
        return sum;
      };
      if (!conformal_chart) {
        grow(false, options.overlap);
      } else {
        // The unfolded band whose map succeeds: to the band's width, or half, or a quarter.
        double unfolded_reach = -1.0, unfolded_radius = 0.0;
        for (int k = 0; k < 3 && unfolded_reach < 0; ++k) {
          if (k > 0) undo();
          const double radius = std::ldexp(options.overlap, -k);
          const std::size_t kept = attempt(true, radius);
          if (kept == kNothingUnfolded) break;
          if (kept > 0) unfolded_reach = band_reach(), unfolded_radius = radius;
        }
        undo();
        attempt(false, options.overlap);
        if (unfolded_reach > band_reach()) {
          undo();
          attempt(true, unfolded_radius);
        }
      }
      {
        // The vertices the chart covers (corners of its faces), and their distance along the
        // surface to where its coverage ends (covered vertices with a face around them it lacks).
        covered.clear();
        coverage_depth(cover, covered, blend_reach);
        // The chart's distortion around each covered vertex (StmOptions::blend): the mean over its
        // faces in the chart of log² σ1 + log² σ2, σ1, σ2 the singular values of the map surface ->
        // chart (both in model units, so 1 where the chart keeps lengths).
        if (blend && distortion_k > 0)
          for (std::uint32_t f : faces) {
            if (face_state[f] != 1) continue;
            glm::dvec2 uv[3];
            face_local(f, c, uv);
            const Triangle& t = mesh.triangles[f];
            const auto sv = face_map_singular_values(glm::dvec3(mesh.positions[t[0]]), glm::dvec3(mesh.positions[t[1]]),
                                                     glm::dvec3(mesh.positions[t[2]]), uv);
            if (!sv) continue;
            const auto [s1, s2] = *sv;
            if (!(s2 > 1e-9)) continue;
            const double delta = std::log(s1) * std::log(s1) + std::log(s2) * std::log(s2);
            for (std::uint32_t v : t) dsum[v] += delta, dcnt[v] += 1;
          }
        for (std::uint32_t v : covered) {
          // The deepest coverage of the vertex over the charts (AtlasMapping::vertex_reach).
          reach[v] = std::max(reach[v], static_cast<float>(cover[v] < 0 ? blend_reach : cover[v]));
          if (!blend) {
            cover[v] = std::numeric_limits<double>::infinity();
            continue;
          }
          double w = cover[v] < 0 ? 1.0 : blend_weight(cover[v]);
          if (distortion_k > 0 && dcnt[v] > 0) w *= std::exp(-distortion_k * dsum[v] / dcnt[v]);
          dsum[v] = 0, dcnt[v] = 0;
          if (vchart[v] == c) own_weight[v] = w;
          else if (w > 1e-4) band_samples.push_back({v, c, w});
          cover[v] = std::numeric_limits<double>::infinity();
        }
      }
      for (std::uint32_t f : faces) face_state[f] = 0;
      for (std::uint32_t v : reached) dist[v] = std::numeric_limits<double>::infinity();
      reached.clear();
    }
  }
  std::vector<glm::dvec2> vlocal(V);
  for (std::size_t v = 0; v < V; ++v) {
    vlocal[v] = vertex_local(vchart[v], static_cast<std::uint32_t>(v));
    ChartMap& m = maps[vchart[v]];
    m.lo = glm::min(m.lo, vlocal[v]);
    m.hi = glm::max(m.hi, vlocal[v]);
  }
  for (ChartMap& m : maps)
    if (m.kind == Chart::Kind::Bone && m.wraps) m.lo.x = 0, m.hi.x = m.width;

  // 6. Scale and packing: the largest texels-per-unit at which the shelf packing fits.
  const std::size_t C = maps.size();
  double total = 0;
  for (const ChartMap& m : maps) total += std::max(m.hi.x - m.lo.x, 0.0) * std::max(m.hi.y - m.lo.y, 0.0);
  const auto sizes = [&](double tpu, std::vector<std::uint32_t>& w, std::vector<std::uint32_t>& h) {
    w.resize(C);
    h.resize(C);
    for (std::size_t c = 0; c < C; ++c) {
      const ChartMap& m = maps[c];
      const double ex = (m.hi.x - m.lo.x) * tpu, ey = (m.hi.y - m.lo.y) * tpu;
      const double cap = 1e9;
      w[c] = m.kind == Chart::Kind::Bone && m.wraps ? static_cast<std::uint32_t>(std::max(3.0, std::min(cap, std::round(ex))))
                                         : static_cast<std::uint32_t>(std::min(cap, std::ceil(ex)) + 1);
      h[c] = static_cast<std::uint32_t>(std::min(cap, std::ceil(ey)) + 1);
    }
  };
  const double size = options.atlas_size;
  double hi_tpu = total > 0 ? size / std::sqrt(total) : size / std::max(diag, 1e-30);
  double lo_tpu = 0;
  std::vector<std::uint32_t> w, h;
  sizes(lo_tpu, w, h);
  Packed best = shelf_pack(w, h, options.atlas_size, options.gutter);
  if (!best.fits)
    throw InputError("skeleton texture mapping: " + std::to_string(C) + " charts do not fit a " +
                     std::to_string(options.atlas_size) + "² atlas with a gutter of " + std::to_string(options.gutter) +
                     " (use a larger atlas)");
  for (int it = 0; it < 48; ++it) {
    const double mid = (lo_tpu + hi_tpu) / 2;
    sizes(mid, w, h);
    Packed p = shelf_pack(w, h, options.atlas_size, options.gutter);
    if (p.fits) lo_tpu = mid, best = std::move(p);
    else hi_tpu = mid;
  }
  const double tpu = lo_tpu;

  // 7. Texel coordinates.
  Stm out;
  AtlasMapping& am = out.mapping;
  am.size = options.atlas_size;
  am.gutter = options.gutter;
  am.charts.resize(C);
  for (std::size_t c = 0; c < C; ++c) {
    Chart& ch = am.charts[c];
    ch.kind = maps[c].kind;
    ch.x0 = best.x[c];
    ch.y0 = best.y[c];
    ch.width = best.w[c];
    ch.height = best.h[c];
    ch.wraps_x = maps[c].kind == Chart::Kind::Bone && maps[c].wraps;
  }
  const auto to_texel = [&](std::uint32_t c, const glm::dvec2& q) {
    const ChartMap& m = maps[c];
    const Chart& ch = am.charts[c];
    double x;
    if (ch.wraps_x) x = ch.x0 + (m.width > 0 ? q.x / m.width * ch.width : 0.5 * ch.width);
    else x = ch.x0 + 0.5 + (q.x - m.lo.x) * tpu;
    const double y = ch.y0 + 0.5 + (q.y - m.lo.y) * tpu;
    return glm::vec2(static_cast<float>(x), static_cast<float>(y));
  };
  am.triangles.reserve(local.size());
  for (const LocalTri& lt : local) {
    AtlasTriangle at;
    at.chart = lt.chart;
    at.face = lt.face;
    for (int k = 0; k < 3; ++k) at.uv[k] = to_texel(lt.chart, lt.uv[k]);
    am.triangles.push_back(at);
  }
  am.vertex_chart = vchart;
  am.vertex_reach = std::move(reach);
  am.vertex_uv.resize(V);
  for (std::size_t v = 0; v < V; ++v) {
    glm::vec2 q = to_texel(vchart[v], vlocal[v]);
    const Chart& ch = am.charts[vchart[v]];
    // Keep float rounding inside the rectangle.
    q.x = std::clamp(q.x, static_cast<float>(ch.x0), std::nextafter(static_cast<float>(ch.x0 + ch.width), 0.0f));
    q.y = std::clamp(q.y, static_cast<float>(ch.y0), std::nextafter(static_cast<float>(ch.y0 + ch.height), 0.0f));
    am.vertex_uv[v] = q;
  }
  if (blend) {
    // The samples: every vertex's own chart, then the bands that cover it; sorted by vertex.
    am.samples.reserve(V + band_samples.size());
    for (std::size_t v = 0; v < V; ++v)
      am.samples.push_back({static_cast<std::uint32_t>(v), vchart[v], am.vertex_uv[v],
                            static_cast<float>(std::max(own_weight[v], 1e-4))});
    for (const BandSample& b : band_samples) {
      glm::vec2 q = to_texel(b.chart, vertex_local(b.chart, b.vertex));
      const Chart& ch = am.charts[b.chart];
      q.x = std::clamp(q.x, static_cast<float>(ch.x0), std::nextafter(static_cast<float>(ch.x0 + ch.width), 0.0f));
      q.y = std::clamp(q.y, static_cast<float>(ch.y0), std::nextafter(static_cast<float>(ch.y0 + ch.height), 0.0f));
      am.samples.push_back({b.vertex, b.chart, q, static_cast<float>(b.weight)});
    }
    std::stable_sort(am.samples.begin(), am.samples.end(),
                     [](const VertexSample& a, const VertexSample& b) { return a.vertex < b.vertex; });
    const ReadCheck reads = keep_reads_that_see_the_vertex(mesh, am);
    out.quality.dropped_own_reads = reads.dropped_own;
    out.quality.borrowed_vertices = reads.borrowed;
  }

  // 8. Quality.
  StmQuality& ql = out.quality;
  ql.charts.resize(C);
  ql.texels_per_unit = tpu;
  std::vector<std::vector<std::pair<double, double>>> area_d(C), angle_d(C);
  std::vector<std::pair<double, double>> all_area, all_angle;
  std::vector<double> texel_area(C, 0.0);
  for (std::size_t v = 0; v < V; ++v) ++ql.charts[vchart[v]].vertices;
  for (const AtlasTriangle& at : am.triangles) {
    ChartQuality& cq = ql.charts[at.chart];
    ++cq.triangles;
    const Triangle& t = mesh.triangles[at.face];
    if (vchart[t[0]] != at.chart || vchart[t[1]] != at.chart || vchart[t[2]] != at.chart) continue;
    const glm::dvec3 p0(mesh.positions[t[0]]), e1 = glm::dvec3(mesh.positions[t[1]]) - p0,
        e2 = glm::dvec3(mesh.positions[t[2]]) - p0;
    const double l1 = glm::length(e1);
    const glm::dvec3 nrm = glm::cross(e1, e2);
    const double a2 = glm::length(nrm);
    if (!(l1 > 0) || !(a2 > 1e-12 * l1 * l1)) continue;
    const glm::dvec3 X = e1 / l1, Y = glm::normalize(glm::cross(nrm, e1));
    // Model triangle in its plane: P1 = (l1, 0), P2 = (e2·X, e2·Y); atlas in model units (÷ tpu).
    const double p2x = glm::dot(e2, X), p2y = glm::dot(e2, Y);
    const glm::dvec2 q1 = glm::dvec2(at.uv[1] - at.uv[0]) / tpu, q2 = glm::dvec2(at.uv[2] - at.uv[0]) / tpu;
    // J [l1 p2x; 0 p2y] = [q1 q2]  →  J = [q1 q2] [1/l1, -p2x/(l1 p2y); 0, 1/p2y].
    const double j00 = q1.x / l1, j10 = q1.y / l1;
    const double j01 = (q2.x - q1.x * p2x / l1) / p2y, j11 = (q2.y - q1.y * p2x / l1) / p2y;
    const auto [s1, s2] = singular_values(j00, j01, j10, j11);
    const double area = a2 / 2;
    cq.area += area;
    texel_area[at.chart] += std::abs(signed_area2(at.uv[0], at.uv[1], at.uv[2])) / 2;
    const double ad = s1 * s2, gd = std::min(kMaxAngleDistortion, s2 > 0 ? s1 / s2 : kMaxAngleDistortion);
    area_d[at.chart].push_back({ad, area});
    angle_d[at.chart].push_back({gd, area});
    all_area.push_back({ad, area});
    all_angle.push_back({gd, area});
  }
  // Coverage: texel centres inside each atlas triangle (wrapping charts: also shifted by ±width),
  // counted per texel.
  {
    std::vector<std::uint8_t> count(static_cast<std::size_t>(am.size) * am.size, 0);
    for (const AtlasTriangle& at : am.triangles) {
      const Chart& ch = am.charts[at.chart];
      for (int sh = ch.wraps_x ? -1 : 0; sh <= (ch.wraps_x ? 1 : 0); ++sh) {
        glm::dvec2 a(at.uv[0]), b(at.uv[1]), c(at.uv[2]);
        a.x += sh * double(ch.width), b.x += sh * double(ch.width), c.x += sh * double(ch.width);
        const double den = signed_area2(a, b, c);
        if (den == 0) continue;
        const long x0 = std::max<long>(ch.x0, static_cast<long>(std::floor(std::min({a.x, b.x, c.x}))));
        const long x1 = std::min<long>(ch.x0 + ch.width - 1, static_cast<long>(std::floor(std::max({a.x, b.x, c.x}))));
        const long y0 = std::max<long>(ch.y0, static_cast<long>(std::floor(std::min({a.y, b.y, c.y}))));
        const long y1 = std::min<long>(ch.y0 + ch.height - 1, static_cast<long>(std::floor(std::max({a.y, b.y, c.y}))));
        for (long y = y0; y <= y1; ++y)
          for (long x = x0; x <= x1; ++x) {
            const glm::dvec2 p(x + 0.5, y + 0.5);
            const double w0 = signed_area2(b, c, p) / den, w1 = signed_area2(c, a, p) / den, w2 = 1 - w0 - w1;
            // Half-open on shared edges (a texel centre exactly on an edge counts once).
            if (w0 < 0 || w1 < 0 || w2 <= 0) continue;
            std::uint8_t& k = count[static_cast<std::size_t>(y) * am.size + static_cast<std::size_t>(x)];
            if (k < 255) ++k;
          }
      }
    }
    std::uint64_t covered = 0, overlapped = 0;
    for (std::size_t c = 0; c < C; ++c) {
      const Chart& ch = am.charts[c];
      for (std::size_t y = ch.y0; y < ch.y0 + ch.height; ++y)
        for (std::size_t x = ch.x0; x < ch.x0 + ch.width; ++x) {
          const std::uint8_t k = count[y * am.size + x];
          ql.charts[c].covered += k > 0;
          ql.charts[c].overlapped += k > 1;
        }
      covered += ql.charts[c].covered;
      overlapped += ql.charts[c].overlapped;
    }
    ql.overlap = covered > 0 ? static_cast<double>(overlapped) / static_cast<double>(covered) : 0.0;
    ql.atlas_covered = static_cast<double>(covered) / (static_cast<double>(am.size) * am.size);
  }
  double used = 0;
  for (std::size_t c = 0; c < C; ++c) {
    ChartQuality& cq = ql.charts[c];
    Chart& ch = am.charts[c];
    cq.kind = ch.kind;
    cq.texels = std::uint64_t{ch.width} * ch.height;
    used += static_cast<double>(cq.texels);
    cq.area_distortion = weighted_stats(std::move(area_d[c]));
    cq.angle_distortion = weighted_stats(std::move(angle_d[c]));
    ch.texels_per_unit = static_cast<float>(cq.area > 0 && texel_area[c] > 0 ? std::sqrt(texel_area[c] / cq.area) : tpu);
    (ch.kind == Chart::Kind::Bone ? ql.bone_charts : ch.kind == Chart::Kind::Joint ? ql.joint_charts : ql.sheet_charts)++;
  }
  std::size_t bone_vertices = 0;
  for (std::size_t v = 0; v < V; ++v) bone_vertices += am.charts[vchart[v]].kind == Chart::Kind::Bone;
  ql.bone_vertex_share = static_cast<double>(bone_vertices) / static_cast<double>(V);
  ql.atlas_used = used / (size * size);
  ql.duplicated_triangles = am.triangles.size() - F;
  ql.area_distortion = weighted_stats(std::move(all_area));
  ql.angle_distortion = weighted_stats(std::move(all_angle));
  ql.band = options.overlap;
  ql.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

std::vector<std::array<glm::vec2, 3>> gltf_corner_uv(const AtlasMapping& mapping, const Mesh& mesh) {
  const std::size_t F = mesh.triangles.size();
  if (mapping.vertex_chart.size() != mesh.positions.size())
    throw InputError("TEXCOORD_1: the atlas mapping does not fit the mesh's vertices");
  std::vector<std::uint32_t> want(F);
  for (std::size_t f = 0; f < F; ++f) {
    const Triangle& t = mesh.triangles[f];
    const std::uint32_t a = mapping.vertex_chart[t[0]], b = mapping.vertex_chart[t[1]], c = mapping.vertex_chart[t[2]];
    want[f] = (b == c && b != a) ? b : a;
  }
  std::vector<std::array<glm::vec2, 3>> out(F);
  std::vector<std::uint8_t> found(F, 0);
  const float s = static_cast<float>(mapping.size);
  for (const AtlasTriangle& at : mapping.triangles) {
    if (at.face >= F || at.chart != want[at.face] || found[at.face]) continue;
    found[at.face] = 1;
    for (int k = 0; k < 3; ++k) out[at.face][static_cast<std::size_t>(k)] = {at.uv[k].x / s, 1.0f - at.uv[k].y / s};
  }
  for (std::size_t f = 0; f < F; ++f)
    if (!found[f]) throw InputError("TEXCOORD_1: face " + std::to_string(f) + " has no atlas triangle in its chart");
  return out;
}

}  // namespace sdfkit::diffusion

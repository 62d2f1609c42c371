// Step 3: the surface of an unoriented cloud as a triangle soup, from a 2D Delaunay
// triangulation of every point's neighbours projected on its tangent plane (the point's star).

#include "sdfkit/pointcloud/pointcloud.hpp"

#include "sdfkit/core/parallel.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace sdfkit::pointcloud {
namespace {

struct Tri {
  std::uint32_t v[3];
  double cx, cy, r2;  // circumcircle
  bool alive;
};

// Circumcircle of a counter-clockwise triangle; r2 = +inf when (nearly) collinear.
void circumcircle(const double* xy, Tri& t) {
  const double ax = xy[2 * t.v[0]], ay = xy[2 * t.v[0] + 1];
  const double bx = xy[2 * t.v[1]], by = xy[2 * t.v[1] + 1];
  const double cx = xy[2 * t.v[2]], cy = xy[2 * t.v[2] + 1];
  const double d = 2.0 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by));
  if (std::abs(d) < 1e-300) {
    t.cx = t.cy = 0.0;
    t.r2 = std::numeric_limits<double>::infinity();
    return;
  }
  const double a2 = ax * ax + ay * ay, b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
  t.cx = (a2 * (by - cy) + b2 * (cy - ay) + c2 * (ay - by)) / d;
  t.cy = (a2 * (cx - bx) + b2 * (ax - cx) + c2 * (bx - ax)) / d;
  t.r2 = (ax - t.cx) * (ax - t.cx) + (ay - t.cy) * (ay - t.cy);
}

double orient(const double* xy, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  return (xy[2 * b] - xy[2 * a]) * (xy[2 * c + 1] - xy[2 * a + 1]) -
         (xy[2 * b + 1] - xy[2 * a + 1]) * (xy[2 * c] - xy[2 * a]);
}

}  // namespace

std::vector<std::array<std::uint32_t, 3>> delaunay_2d(std::span<const float> xy_in) {
  const std::size_t n = xy_in.size() / 2;
  std::vector<std::array<std::uint32_t, 3>> result;
  if (n < 3) return result;
  // Normalized copy plus three super-triangle vertices at n, n+1, n+2.
  double minx = xy_in[0], maxx = xy_in[0], miny = xy_in[1], maxy = xy_in[1];
  for (std::size_t i = 0; i < n; ++i) {
    minx = std::min<double>(minx, xy_in[2 * i]);
    maxx = std::max<double>(maxx, xy_in[2 * i]);
    miny = std::min<double>(miny, xy_in[2 * i + 1]);
    maxy = std::max<double>(maxy, xy_in[2 * i + 1]);
  }
  const double scale = std::max({maxx - minx, maxy - miny, 1e-30});
  std::vector<double> xy(2 * (n + 3));
  for (std::size_t i = 0; i < n; ++i) {
    xy[2 * i] = (xy_in[2 * i] - minx) / scale;
    xy[2 * i + 1] = (xy_in[2 * i + 1] - miny) / scale;
  }
  const double big = 100.0;
  const std::uint32_t s0 = static_cast<std::uint32_t>(n);
  xy[2 * n] = -big; xy[2 * n + 1] = -big;
  xy[2 * n + 2] = big; xy[2 * n + 3] = -big;
  xy[2 * n + 4] = 0.5; xy[2 * n + 5] = big;
  std::vector<Tri> tris;
  tris.reserve(4 * n + 8);
  Tri first{{s0, s0 + 1, s0 + 2}, 0, 0, 0, true};
  circumcircle(xy.data(), first);
  tris.push_back(first);
  std::vector<std::array<std::uint32_t, 2>> edges;
  std::vector<std::uint32_t> inserted;
  for (std::uint32_t p = 0; p < n; ++p) {
    const double px = xy[2 * p], py = xy[2 * p + 1];
    bool duplicate = false;
    for (std::uint32_t q : inserted)
      if (std::abs(xy[2 * q] - px) < 1e-12 && std::abs(xy[2 * q + 1] - py) < 1e-12) duplicate = true;
    if (duplicate) continue;
    inserted.push_back(p);
    edges.clear();
    for (Tri& t : tris) {
      if (!t.alive) continue;
      const double dx = px - t.cx, dy = py - t.cy;
      if (dx * dx + dy * dy < t.r2 * (1.0 - 1e-12)) {
        t.alive = false;
        for (int e = 0; e < 3; ++e) edges.push_back({t.v[e], t.v[(e + 1) % 3]});
      }
    }
    // The cavity's boundary: edges that appear once (an inner edge appears in both directions).
    for (std::size_t a = 0; a < edges.size(); ++a) {
      bool shared = false;
      for (std::size_t b = 0; b < edges.size(); ++b)
        if (a != b && edges[a][0] == edges[b][1] && edges[a][1] == edges[b][0]) shared = true;
      if (shared) continue;
      Tri t{{edges[a][0], edges[a][1], p}, 0, 0, 0, true};
      if (orient(xy.data(), t.v[0], t.v[1], t.v[2]) <= 0.0) continue;  // degenerate sliver
      circumcircle(xy.data(), t);
      tris.push_back(t);
    }
    if (tris.size() > 64 * (n + 3)) {  // compact dead triangles now and then
      tris.erase(std::remove_if(tris.begin(), tris.end(), [](const Tri& t) { return !t.alive; }), tris.end());
    }
  }
  for (const Tri& t : tris)
    if (t.alive && t.v[0] < n && t.v[1] < n && t.v[2] < n) result.push_back({t.v[0], t.v[1], t.v[2]});
  return result;
}

std::vector<std::array<std::uint32_t, 2>> delaunay_star(std::span<const float> xy) {
  // The Voronoi cell of the origin: a square far outside the neighbours, clipped by the
  // bisector half-plane x . q <= |q|^2 / 2 of every neighbour q. Each cell edge keeps the
  // neighbour whose bisector made it (-1: the square, an unbounded side).
  const std::size_t n = xy.size() / 2;
  std::vector<std::array<std::uint32_t, 2>> star;
  double reach = 0.0;
  for (std::size_t j = 0; j < n; ++j) reach = std::max(reach, std::hypot(double(xy[2 * j]), double(xy[2 * j + 1])));
  if (reach <= 0.0) return star;
  const double box = 8.0 * reach;
  struct V {
    double x, y;
    int label;  // the edge from this vertex to the next
  };
  std::vector<V> poly{{-box, -box, -1}, {box, -box, -1}, {box, box, -1}, {-box, box, -1}}, next;
  for (std::size_t j = 0; j < n; ++j) {
    const double qx = xy[2 * j], qy = xy[2 * j + 1];
    const double c = 0.5 * (qx * qx + qy * qy);
    if (c <= 1e-12 * reach * reach) continue;  // a duplicate of the centre
    next.clear();
    const std::size_t m = poly.size();
    for (std::size_t i = 0; i < m; ++i) {
      const V& a = poly[i];
      const V& b = poly[(i + 1) % m];
      const double fa = a.x * qx + a.y * qy - c, fb = b.x * qx + b.y * qy - c;
      const bool ina = fa <= 0.0, inb = fb <= 0.0;
      if (ina) next.push_back(a);
      if (ina != inb) {
        const double u = fa / (fa - fb);
        const V cut{a.x + u * (b.x - a.x), a.y + u * (b.y - a.y), ina ? static_cast<int>(j) : a.label};
        next.push_back(cut);
      }
    }
    poly.swap(next);
    if (poly.size() < 3) return star;
  }
  // Consecutive cell edges made by two neighbours i then j: the Delaunay triangle (0, i, j).
  const std::size_t m = poly.size();
  for (std::size_t i = 0; i < m; ++i) {
    const int a = poly[i].label, b = poly[(i + 1) % m].label;
    if (a >= 0 && b >= 0 && a != b) star.push_back({static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b)});
  }
  return star;
}

Mesh tangent_plane_surface(std::span<const glm::vec3> points, std::span<const glm::vec3> normals,
                           const Neighbours& nb, bool deduplicate) {
  const std::size_t n = points.size();
  std::vector<std::vector<Triangle>> stars(n);
  parallel_for(n, [&](std::size_t begin, std::size_t end) {
    std::vector<float> xy;
    for (std::size_t i = begin; i < end; ++i) {
      const glm::vec3 nrm = normals[i];
      const glm::vec3 helper = std::abs(nrm.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
      const glm::vec3 u = glm::normalize(glm::cross(nrm, helper));
      const glm::vec3 v = glm::cross(nrm, u);  // (u, v, n) right-handed
      const auto ids = nb.of(i);
      xy.assign(2 * ids.size(), 0.0f);
      for (std::size_t j = 0; j < ids.size(); ++j) {
        const glm::vec3 d = points[ids[j]] - points[i];
        xy[2 * j] = glm::dot(d, u);
        xy[2 * j + 1] = glm::dot(d, v);
      }
      for (const auto& e : delaunay_star(xy)) stars[i].push_back({static_cast<std::uint32_t>(i), ids[e[0]], ids[e[1]]});
    }
  }, 2048);  // about 1.2 us a point: the worm (1421 points) runs on one thread
  Mesh mesh;
  mesh.positions.assign(points.begin(), points.end());
  std::size_t total = 0;
  for (const auto& s : stars) total += s.size();
  mesh.triangles.reserve(total);
  for (const auto& s : stars) mesh.triangles.insert(mesh.triangles.end(), s.begin(), s.end());
  if (deduplicate && !mesh.triangles.empty()) {
    std::vector<std::pair<Triangle, std::uint32_t>> keyed(mesh.triangles.size());
    for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
      Triangle key = mesh.triangles[f];
      std::sort(key.begin(), key.end());
      keyed[f] = {key, static_cast<std::uint32_t>(f)};
    }
    std::sort(keyed.begin(), keyed.end());
    std::vector<Triangle> unique;
    unique.reserve(keyed.size() / 2);
    for (std::size_t f = 0; f < keyed.size(); ++f)
      if (f == 0 || keyed[f].first != keyed[f - 1].first) unique.push_back(mesh.triangles[keyed[f].second]);
    mesh.triangles = std::move(unique);
  }
  return mesh;
}

}  // namespace sdfkit::pointcloud

// The skeleton's steps one by one, without a device: neighbours against brute force, PCA
// normals on analytic surfaces, MST orientation, the 2D Delaunay (empty circles, the fast star
// against Bowyer-Watson), the tangent-plane surface, the clustering's merge tree, resampling and
// the head/tail matching of a sequence.
#include "sdfkit/core/error.hpp"
#include "sdfkit/pointcloud/pointcloud.hpp"

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <numeric>
#include <random>
#include <set>

namespace pc = sdfkit::pointcloud;

namespace {

// Points on a sphere (Fibonacci lattice), radius r around c.
std::vector<glm::vec3> sphere_points(std::size_t n, float r, glm::vec3 c = glm::vec3(0.0f)) {
  std::vector<glm::vec3> p(n);
  const float golden = std::numbers::pi_v<float> * (3.0f - std::sqrt(5.0f));
  for (std::size_t i = 0; i < n; ++i) {
    const float y = 1.0f - 2.0f * (static_cast<float>(i) + 0.5f) / static_cast<float>(n);
    const float rad = std::sqrt(1.0f - y * y);
    const float t = golden * static_cast<float>(i);
    p[i] = c + r * glm::vec3(std::cos(t) * rad, y, std::sin(t) * rad);
  }
  return p;
}

}  // namespace

TEST(PointcloudNeighbours, MatchBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<glm::vec3> pts(500);
  for (auto& p : pts) p = {u(rng), u(rng), u(rng)};
  const pc::Neighbours nb = pc::k_nearest(pts, 7);
  ASSERT_EQ(nb.k, 7);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    std::vector<std::pair<float, std::uint32_t>> all;
    for (std::size_t j = 0; j < pts.size(); ++j)
      if (j != i) all.push_back({glm::dot(pts[i] - pts[j], pts[i] - pts[j]), static_cast<std::uint32_t>(j)});
    std::sort(all.begin(), all.end());
    for (int k = 0; k < 7; ++k) {
      EXPECT_EQ(nb.of(i)[k], all[k].second) << "point " << i << " rank " << k;
      EXPECT_FLOAT_EQ(nb.dist2[i * 7 + k], all[k].first);
    }
  }
  // k larger than the cloud: lowered to n - 1; the sparse view keeps the nearest.
  EXPECT_EQ(pc::k_nearest(std::vector<glm::vec3>(pts.begin(), pts.begin() + 5), 12).k, 4);
  const pc::Neighbours first = pc::first_neighbours(nb, 3);
  EXPECT_EQ(first.of(10)[2], nb.of(10)[2]);
  EXPECT_THROW(pc::k_nearest(pts, 0), sdfkit::InputError);
}

TEST(PointcloudNormals, SphereNormalsAreRadialAndOrientedOutward) {
  const auto pts = sphere_points(2000, 3.0f, {1, 2, 3});
  const pc::Neighbours nb = pc::k_nearest(pts, pc::kDefaultNeighbours);
  const auto raw = pc::pca_normals(pts, nb);
  const pc::Orientation o = pc::orient_normals_mst(pts, raw, nb, 1);
  EXPECT_EQ(o.components, 1u);
  EXPECT_TRUE(o.ambiguous.empty());
  // The seed is the topmost point; every normal points away from the centre.
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_LE(pts[i].y, pts[o.seed].y);
    const glm::vec3 radial = glm::normalize(pts[i] - glm::vec3(1, 2, 3));
    EXPECT_NEAR(std::abs(glm::dot(raw[i], radial)), 1.0f, 2e-3f);
    EXPECT_GT(glm::dot(o.normals[i], radial), 0.99f) << i;
  }
}

TEST(PointcloudNormals, PlaneNormalsAndSeedAxis) {
  std::vector<glm::vec3> pts;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j) pts.push_back({0.1f * i + 0.013f * j * j / 20.0f, 0.5f, 0.1f * j});
  const pc::Neighbours nb = pc::k_nearest(pts, 8);
  const auto raw = pc::pca_normals(pts, nb);
  for (const auto& n : raw) EXPECT_NEAR(std::abs(n.y), 1.0f, 1e-3f);
  // Seeded along y: every normal points +y (out of the plane's "top").
  const auto o = pc::orient_normals_mst(pts, raw, nb, 1);
  for (const auto& n : o.normals) EXPECT_GT(n.y, 0.99f);
  EXPECT_THROW(pc::orient_normals_mst(pts, raw, nb, 3), sdfkit::InputError);
}

TEST(PointcloudNormals, TwoSeparateSpheresAreEachSeeded) {
  auto a = sphere_points(400, 1.0f);
  const auto b = sphere_points(400, 1.0f, {10, 0, 0});
  a.insert(a.end(), b.begin(), b.end());
  const pc::Neighbours nb = pc::k_nearest(a, 10);
  const auto o = pc::orient_normals_mst(a, pc::pca_normals(a, nb), nb, 1);
  EXPECT_EQ(o.components, 2u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    const glm::vec3 c = i < 400 ? glm::vec3(0) : glm::vec3(10, 0, 0);
    EXPECT_GT(glm::dot(o.normals[i], glm::normalize(a[i] - c)), 0.95f);
  }
}

TEST(PointcloudDelaunay, EmptyCirclesAndCcw) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<float> xy(2 * 15);
    for (float& v : xy) v = u(rng);
    const auto tris = pc::delaunay_2d(xy);
    // Euler: a triangulation of n points with h on the hull has 2n - 2 - h triangles; at least n - 2.
    EXPECT_GE(tris.size(), 13u);
    for (const auto& t : tris) {
      const double ax = xy[2 * t[0]], ay = xy[2 * t[0] + 1], bx = xy[2 * t[1]], by = xy[2 * t[1] + 1],
                   cx = xy[2 * t[2]], cy = xy[2 * t[2] + 1];
      EXPECT_GT((bx - ax) * (cy - ay) - (by - ay) * (cx - ax), 0.0);
      for (std::size_t p = 0; p < 15; ++p) {
        if (p == t[0] || p == t[1] || p == t[2]) continue;
        const double dx[3] = {ax - xy[2 * p], bx - xy[2 * p], cx - xy[2 * p]};
        const double dy[3] = {ay - xy[2 * p + 1], by - xy[2 * p + 1], cy - xy[2 * p + 1]};
        double m[3][3];
        for (int r = 0; r < 3; ++r) m[r][0] = dx[r], m[r][1] = dy[r], m[r][2] = dx[r] * dx[r] + dy[r] * dy[r];
        const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        EXPECT_LE(det, 1e-9) << "point " << p << " inside a circumcircle";
      }
    }
  }
  EXPECT_TRUE(pc::delaunay_2d(std::vector<float>{0, 0, 1, 1}).empty());
}

TEST(PointcloudDelaunay, StarFromVoronoiCellMatchesBowyerWatson) {
  std::mt19937 rng(11);
  std::normal_distribution<float> g(0.0f, 1.0f);
  int compared = 0;
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<float> nbrs(2 * 12);
    for (float& v : nbrs) v = g(rng);
    std::vector<float> all{0.0f, 0.0f};
    all.insert(all.end(), nbrs.begin(), nbrs.end());
    std::set<std::pair<std::uint32_t, std::uint32_t>> bw, star;
    for (const auto& t : pc::delaunay_2d(all))
      for (int k = 0; k < 3; ++k)
        if (t[k] == 0) bw.insert({t[(k + 1) % 3] - 1, t[(k + 2) % 3] - 1});
    for (const auto& e : pc::delaunay_star(nbrs)) star.insert({e[0], e[1]});
    // The origin inside its neighbours' hull: both stars are the same closed fan.
    EXPECT_EQ(star, bw) << "trial " << trial;
    compared += !star.empty();
  }
  EXPECT_GT(compared, 150);
}

TEST(PointcloudSurface, SphereSurfaceIsClosedAndOutward) {
  const auto pts = sphere_points(1500, 2.0f);
  const pc::Neighbours nb = pc::k_nearest(pts, pc::kDefaultNeighbours);
  const auto o = pc::orient_normals_mst(pts, pc::pca_normals(pts, nb), nb, 1);
  const sdfkit::Mesh soup = pc::tangent_plane_surface(pts, o.normals, nb, false);
  const sdfkit::Mesh mesh = pc::tangent_plane_surface(pts, o.normals, nb, true);
  EXPECT_GT(soup.triangles.size(), mesh.triangles.size());  // stars overlap: duplicates
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& t : mesh.triangles) {
    const glm::vec3 n = glm::cross(pts[t[1]] - pts[t[0]], pts[t[2]] - pts[t[0]]);
    EXPECT_GT(glm::dot(n, pts[t[0]] + pts[t[1]] + pts[t[2]]), 0.0f);  // outward
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  }
  // Closed: every directed edge has its opposite.
  std::size_t open = 0;
  for (const auto& [e, c] : directed) open += directed.count({e.second, e.first}) == 0;
  EXPECT_EQ(open, 0u);
  // About 2 triangles per point on a closed surface.
  EXPECT_NEAR(static_cast<double>(mesh.triangles.size()) / pts.size(), 2.0, 0.1);
}

TEST(PointcloudClustering, MergeTreeCountsAreMonotoneAndLabelsConsistent) {
  // Points along a line with a little spread: clusters shrink as the threshold grows.
  std::vector<glm::vec3> pts;
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(-0.05f, 0.05f);
  for (int i = 0; i < 400; ++i) pts.push_back({0.25f * i, u(rng), u(rng)});
  const pc::Neighbours nb = pc::k_nearest(pts, 6);
  for (auto linkage : {pc::Linkage::Average, pc::Linkage::Single}) {
    const pc::MergeTree tree(pts, nb, linkage);
    EXPECT_EQ(tree.merge_count(), 399u);
    std::size_t last = pts.size() + 1;
    for (float t = 0.0f; t < 60.0f; t += 0.5f) {
      const std::size_t c = tree.cluster_count(t);
      EXPECT_LE(c, last);
      last = c;
      const auto labels = tree.labels(t);
      EXPECT_EQ(*std::max_element(labels.begin(), labels.end()) + 1, c);
    }
    EXPECT_EQ(tree.cluster_count(1e9f), 1u);
    if (linkage == pc::Linkage::Single) {
      EXPECT_EQ(tree.cluster_count(0.3f), 1u);  // chaining: one cluster
    }
  }
  // Average linkage on a line: clusters are runs of consecutive points of similar length; the
  // ordered polyline follows the line.
  const pc::MergeTree avg(pts, nb, pc::Linkage::Average);
  const std::vector<float> sdf(pts.size(), 1.0f);
  const pc::SegmentSearch s = pc::polyline_with_segments(pts, sdf, avg, nb, 10);
  ASSERT_EQ(s.polyline.nodes.size(), 11u);
  for (std::size_t i = 1; i < s.polyline.nodes.size(); ++i) {
    const float dx = s.polyline.nodes[i].position.x - s.polyline.nodes[i - 1].position.x;
    EXPECT_GT(std::abs(dx), 3.0f);
    EXPECT_EQ(dx > 0.0f, s.polyline.nodes[1].position.x > s.polyline.nodes[0].position.x);  // monotone
    EXPECT_FLOAT_EQ(s.polyline.nodes[i].radius, 0.5f);
  }
  EXPECT_THROW(pc::polyline_with_segments(pts, sdf, avg, nb, 0), sdfkit::InputError);
}

TEST(PointcloudSdf, MedianFilterRemovesAnIsolatedOutlierAndKeepsALinearField) {
  std::vector<glm::vec3> pts;
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 30; ++j) pts.push_back({0.5f * i, 0.5f * j, 0.0f});
  const pc::Neighbours nb = pc::k_nearest(pts, 8);
  std::vector<float> sdf(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) sdf[i] = 2.0f + 0.1f * pts[i].x;
  const std::size_t centre = 15 * 30 + 15;
  std::vector<float> spiked = sdf;
  spiked[centre] = 40.0f;  // a ray bundle through a gap
  const auto out = pc::median_filter(spiked, nb);
  ASSERT_EQ(out.size(), sdf.size());
  EXPECT_NEAR(out[centre], sdf[centre], 0.051f);
  // Interior points (a symmetric 8-neighbourhood): the linear field is unchanged.
  const auto lin = pc::median_filter(sdf, nb);
  for (int i = 2; i < 28; ++i)
    for (int j = 2; j < 28; ++j) EXPECT_NEAR(lin[i * 30 + j], sdf[i * 30 + j], 1e-5f);
  EXPECT_THROW(pc::median_filter(std::vector<float>(5, 1.0f), nb), sdfkit::InputError);
}

// Average linkage by brute force: at every step the adjacent pair of clusters (over the graph)
// with the smallest root-mean-square point distance, computed from the points themselves.
TEST(PointcloudClustering, AverageLinkageMergesAreTheGreedySequence) {
  std::vector<glm::vec3> pts;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 160; ++i) pts.push_back({4.0f * u(rng), u(rng), 0.5f * u(rng)});
  const pc::Neighbours nb = pc::k_nearest(pts, 5);
  const pc::MergeTree tree(pts, nb, pc::Linkage::Average);
  std::vector<int> label(pts.size());
  std::iota(label.begin(), label.end(), 0);
  std::set<std::pair<int, int>> edges;
  for (std::size_t i = 0; i < pts.size(); ++i)
    for (std::uint32_t j : nb.of(i)) edges.insert({std::min<int>(i, j), std::max<int>(i, j)});
  std::vector<std::vector<std::size_t>> members(pts.size());
  auto rms = [&](int a, int b) {
    double s = 0.0;
    for (std::size_t i : members[a])
      for (std::size_t j : members[b]) s += glm::dot(pts[i] - pts[j], pts[i] - pts[j]);
    return std::sqrt(s / static_cast<double>(members[a].size() * members[b].size()));
  };
  const auto heights = tree.merge_heights();
  ASSERT_EQ(heights.size(), pts.size() - 1);  // the 5-neighbour graph of this cloud is connected
  for (std::size_t m = 0; m < heights.size(); ++m) {
    for (auto& v : members) v.clear();
    for (std::size_t i = 0; i < pts.size(); ++i) members[label[i]].push_back(i);
    std::set<std::pair<int, int>> pairs;
    for (const auto& [i, j] : edges)
      if (label[i] != label[j]) pairs.insert({std::min(label[i], label[j]), std::max(label[i], label[j])});
    double best = 1e30;
    std::pair<int, int> pick{-1, -1};
    for (const auto& p : pairs) {
      const double d = rms(p.first, p.second);
      if (d < best) {
        best = d;
        pick = p;
      }
    }
    ASSERT_NEAR(heights[m], best, 1e-4 * (1.0 + best)) << "merge " << m;
    for (int& l : label)
      if (l == pick.second) l = pick.first;
  }
}

TEST(PointcloudPolyline, ResampleAndDistances) {
  pc::Polyline l;
  l.nodes = {{{0, 0, 0}, 1.0f}, {{3, 0, 0}, 2.0f}, {{3, 4, 0}, 4.0f}};
  EXPECT_FLOAT_EQ(l.length(), 7.0f);
  const pc::Polyline r = pc::resample(l, 8);
  ASSERT_EQ(r.nodes.size(), 8u);
  EXPECT_NEAR(r.length(), 7.0f - 0.0f, 0.6f);  // the corner is cut once
  EXPECT_EQ(r.nodes.front().position, l.nodes.front().position);
  EXPECT_EQ(r.nodes.back().position, l.nodes.back().position);
  EXPECT_NEAR(r.nodes[3].position.x, 3.0f, 1e-5f);  // s = 3: the corner
  EXPECT_NEAR(r.nodes[3].radius, 2.0f, 1e-5f);
  EXPECT_FLOAT_EQ(pc::distance_to_polyline({1, 1, 0}, l), 1.0f);
  EXPECT_NEAR(pc::mean_distance(l, l, 0.1f), 0.0f, 1e-6f);
  pc::Polyline shifted = l;
  for (auto& n : shifted.nodes) n.position.z += 0.5f;
  EXPECT_NEAR(pc::mean_distance(shifted, l, 0.1f), 0.5f, 1e-5f);
  EXPECT_THROW(pc::resample(l, 1), sdfkit::InputError);
}

TEST(PointcloudPolyline, SequenceKeepsTheSameEndFirst) {
  std::vector<pc::Polyline> frames(6);
  for (int f = 0; f < 6; ++f) {
    for (int i = 0; i < 5; ++i) frames[f].nodes.push_back({{i + 0.1f * f, 0.2f * f, 0}, 1.0f});
    if (f % 2) std::reverse(frames[f].nodes.begin(), frames[f].nodes.end());
  }
  EXPECT_EQ(pc::orient_sequence(frames), 3u);
  for (const auto& l : frames) EXPECT_LT(l.nodes.front().position.x, l.nodes.back().position.x);
}

TEST(PointcloudSynthetic, WormMidlineHasTheAskedLengthAndPointsLieOnTheTube) {
  pc::WormShape shape;
  shape.noise = 0.0f;
  const pc::SyntheticWorm w = pc::synthetic_worm(shape);
  EXPECT_EQ(w.points.size(), shape.points);
  EXPECT_NEAR(w.midline.length(), shape.length, 0.01f * shape.length);
  // Noise-free points lie at the tube's radius from the axis (the closest axis point's radius).
  int checked = 0;
  for (std::size_t i = 0; i < w.points.size(); i += 7) {
    float best = 1e9f, radius = 0.0f;
    for (std::size_t j = 1; j < w.midline.nodes.size(); ++j) {
      const float d = glm::distance(w.points[i], w.midline.nodes[j].position);
      if (d < best) {
        best = d;
        radius = w.midline.nodes[j].radius;
      }
    }
    if (radius > 0.9f * shape.max_radius) {  // body, away from the tips
      EXPECT_NEAR(pc::distance_to_polyline(w.points[i], w.midline), radius, 0.05f);
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

// Skeleton texture mapping on analytic shapes with skeletons built by hand (so the expected
// charts are known): a capsule (one bone, two end caps; the bone chart is isometric up to the
// polygon's chords), a torus (a loop cut at one node), a box as a sheet, a star of three bones
// at a junction. Plus input errors, the skeleton JSON reader and the atlas PNG.
#include "sdfkit/core/error.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/diffusion/stm.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "scratch.hpp"
#include "stm_check.hpp"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

using namespace sdfkit;
namespace sk = sdfkit::skeleton;
namespace dif = sdfkit::diffusion;

namespace {

// A skeleton whose nodes sit at `points`, chained by edges i–i+1 (closed: also last–first),
// every mesh vertex in the node nearest to it.
sk::Skeleton polyline_skeleton(const Mesh& mesh, const std::vector<glm::vec3>& points, bool closed, float radius) {
  sk::Skeleton s;
  for (const glm::vec3& p : points) s.nodes.push_back({p, radius, {}, false});
  for (std::uint32_t i = 0; i + 1 < points.size(); ++i) s.edges.push_back({i, i + 1});
  if (closed) s.edges.push_back({0, static_cast<std::uint32_t>(points.size() - 1)});
  for (std::uint32_t v = 0; v < mesh.positions.size(); ++v) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < points.size(); ++i)
      if (glm::length(mesh.positions[v] - points[i]) < glm::length(mesh.positions[v] - points[best])) best = i;
    s.nodes[best].vertices.push_back(v);
  }
  return s;
}

const float kRadius = 0.5f, kLength = 3.0f;

Mesh capsule() { return shapes::capsule(kRadius, kLength, 64, 48); }

sk::Skeleton capsule_skeleton(const Mesh& mesh) {
  std::vector<glm::vec3> pts;
  for (int i = 0; i <= 6; ++i) pts.push_back({0.0f, 0.0f, -kLength / 2 + kLength * static_cast<float>(i) / 6.0f});
  return polyline_skeleton(mesh, pts, false, kRadius);
}

const dif::ChartQuality* only_bone(const dif::Stm& stm) {
  const dif::ChartQuality* bone = nullptr;
  for (const dif::ChartQuality& c : stm.quality.charts)
    if (c.kind == dif::Chart::Kind::Bone) {
      if (bone) return nullptr;
      bone = &c;
    }
  return bone;
}

}  // namespace

TEST(Stm, CapsuleIsOneIsometricBoneChartAndTwoCaps) {
  const Mesh mesh = capsule();
  const dif::Stm stm = dif::build_stm(mesh, capsule_skeleton(mesh));
  test::expect_valid_stm(mesh, stm);
  ASSERT_EQ(stm.quality.bone_charts, 1u);
  EXPECT_EQ(stm.quality.joint_charts, 2u) << "one cap at each end";
  const dif::ChartQuality* bone = only_bone(stm);
  ASSERT_NE(bone, nullptr);
  // The analytic map of the cylinder: x = angle × r, y = z, an isometry of the smooth surface.
  // The mesh is a 64-gon prism: an edge of chord 2r sin(π/64) maps to the arc 2πr/64, a factor
  // (π/64)/sin(π/64) = 1.0004, and the width rounds to whole texels (under 1/2 texel in ~1000).
  EXPECT_NEAR(bone->area_distortion.mean, 1.0, 0.005);
  EXPECT_NEAR(bone->area_distortion.max, 1.0, 0.005);
  EXPECT_NEAR(bone->angle_distortion.p95, 1.0, 0.005);
  EXPECT_NEAR(bone->angle_distortion.max, 1.0, 0.005);
  // The cylinder's side area 2π r L, all in the bone chart (its triangles only).
  EXPECT_NEAR(bone->area, 2 * M_PI * kRadius * kLength, 0.01 * 2 * M_PI * kRadius * kLength);
  // Caps: stereographic projection of the directions around the hemisphere's centre, conformal
  // on the smooth hemisphere (measured here: 1.06 on the flat facets and whatever cylinder
  // triangles the cap chart holds; the equidistant map's angle distortion reached π/2 at the rim),
  // with the scale 1 / cos²(θ/2): area distortion from 1 at the pole to 1 / cos⁴(45°) = 4 at the
  // rim.
  for (const dif::ChartQuality& c : stm.quality.charts) {
    if (c.kind != dif::Chart::Kind::Joint) continue;
    EXPECT_LE(c.area_distortion.max, 4.0 * 1.05);
    EXPECT_GE(c.area_distortion.mean, 0.95);
    EXPECT_LE(c.angle_distortion.max, 1.1);
  }
  EXPECT_GT(stm.quality.atlas_used, 0.3) << "the shelf packing of three rectangles";
  EXPECT_LT(stm.quality.overlap, 1e-3) << "no chart folds over itself";
}

TEST(Stm, BoneChartWrapsAndSeamTrianglesAreUnwrapped) {
  // Turned by a third of a ring edge around the axis, so that the angle seam crosses triangles
  // instead of running along a column of vertices.
  const float a = static_cast<float>(2 * M_PI / 64 / 3), c = std::cos(a), s = std::sin(a);
  const float turn[16] = {c, s, 0, 0, -s, c, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  const Mesh mesh = transformed(capsule(), turn);
  const dif::Stm stm = dif::build_stm(mesh, capsule_skeleton(mesh));
  std::size_t bone = 0;
  while (stm.mapping.charts[bone].kind != dif::Chart::Kind::Bone) ++bone;
  const dif::Chart& ch = stm.mapping.charts[bone];
  ASSERT_TRUE(ch.wraps_x);
  std::size_t across = 0;
  for (const dif::AtlasTriangle& t : stm.mapping.triangles) {
    if (t.chart != bone) continue;
    float lo = 1e30f, hi = -1e30f;
    for (const glm::vec2& q : t.uv) lo = std::min(lo, q.x), hi = std::max(hi, q.x);
    EXPECT_LT(hi - lo, 0.1f * static_cast<float>(ch.width)) << "a 64-gon's triangle spans 1/64 of the angle";
    across += lo < static_cast<float>(ch.x0) || hi > static_cast<float>(ch.x0 + ch.width);
  }
  EXPECT_GT(across, 0u) << "some triangles straddle the seam";
  // The texel width of one 64th of the angle equals the model length of a ring edge × scale.
  const double ring_edge = 2 * kRadius * std::sin(M_PI / 64);
  EXPECT_NEAR(ch.width / 64.0, ring_edge * stm.quality.texels_per_unit, 0.01 * ch.width / 64.0 + 0.5 / 64);
}

TEST(Stm, OutputIsDeterministic) {
  const Mesh mesh = capsule();
  const sk::Skeleton s = capsule_skeleton(mesh);
  const dif::Stm a = dif::build_stm(mesh, s), b = dif::build_stm(mesh, s);
  ASSERT_EQ(a.mapping.charts.size(), b.mapping.charts.size());
  ASSERT_EQ(a.mapping.triangles.size(), b.mapping.triangles.size());
  for (std::size_t i = 0; i < a.mapping.charts.size(); ++i) {
    EXPECT_EQ(a.mapping.charts[i].x0, b.mapping.charts[i].x0);
    EXPECT_EQ(a.mapping.charts[i].width, b.mapping.charts[i].width);
  }
  EXPECT_EQ(0, std::memcmp(a.mapping.triangles.data(), b.mapping.triangles.data(),
                           a.mapping.triangles.size() * sizeof(dif::AtlasTriangle)));
  EXPECT_EQ(a.mapping.vertex_chart, b.mapping.vertex_chart);
  EXPECT_EQ(0, std::memcmp(a.mapping.vertex_uv.data(), b.mapping.vertex_uv.data(),
                           a.mapping.vertex_uv.size() * sizeof(glm::vec2)));
}

TEST(Stm, AtlasSizeAndGutterAreHonoured) {
  const Mesh mesh = capsule();
  const sk::Skeleton s = capsule_skeleton(mesh);
  dif::StmOptions o;
  o.atlas_size = 512;
  o.gutter = 6;
  const dif::Stm small = dif::build_stm(mesh, s, o);
  test::expect_valid_stm(mesh, small, o);
  const dif::Stm big = dif::build_stm(mesh, s);
  // Same charts, about 4× the scale (the gutter and rounding take a little).
  EXPECT_NEAR(big.quality.texels_per_unit / small.quality.texels_per_unit, 4.0, 0.25);
}

// A torus's skeleton is a loop of degree-2 nodes: cut at one node, whose vertices form a
// planar joint chart, so no triangle of the bone chart reaches from one end of the loop to the
// other.
TEST(Stm, TorusLoopIsCutAtOneNode) {
  const Mesh mesh = shapes::torus(1.0f, 0.3f, 64, 24);
  std::vector<glm::vec3> pts;
  for (int i = 0; i < 16; ++i) {
    const float a = static_cast<float>(i) / 16.0f * 6.2831853f;
    pts.push_back({std::cos(a), std::sin(a), 0.0f});
  }
  const dif::Stm stm = dif::build_stm(mesh, polyline_skeleton(mesh, pts, true, 0.3f));
  test::expect_valid_stm(mesh, stm);
  EXPECT_EQ(stm.quality.bone_charts, 1u);
  EXPECT_GE(stm.quality.joint_charts, 1u);
  EXPECT_GT(stm.quality.bone_vertex_share, 0.8);
  // The analytic bound: along the ring, the inner side (radius R - r = 0.7) of a 16-gon's
  // segment maps to the chord 2 sin(π/16) = 0.390 from an arc 0.7 · 2π/16 = 0.275, a factor
  // 1.42; around the tube, x is scaled by the median distance to the polyline (0.3) while the
  // chord's middle is 1 - cos(π/16) = 0.019 closer to the inner side: ≤ 0.3/0.281 = 1.068. Their
  // product 1.516 bounds the area distortion (measured: 1.517, the float rounding of the atlas).
  const dif::ChartQuality* bone = only_bone(stm);
  ASSERT_NE(bone, nullptr);
  EXPECT_LE(bone->area_distortion.max, 1.53);
  EXPECT_GE(bone->area_distortion.mean, 0.8);
}

// A junction: the capsule's middle node gets a third edge (a stub into the solid), so the axis
// is two bones meeting at a node of degree 3 (and the stub a third). Vertices around the
// junction go to a bone or a planar joint chart, never folded.
TEST(Stm, JunctionNodeGetsPlanarJointCharts) {
  const Mesh mesh = capsule();
  sk::Skeleton s = capsule_skeleton(mesh);
  // A stub edge from the middle node (3) to a node inside the capsule: node 3 has degree 3.
  s.nodes.push_back({{0.2f, 0.0f, 0.0f}, kRadius, {}, false});
  s.edges.push_back({3, 7});
  const dif::Stm stm = dif::build_stm(mesh, s);
  test::expect_valid_stm(mesh, stm);
  EXPECT_GE(stm.quality.bone_charts, 2u);
}

// A box whose every node is a sheet node: planar charts by face direction, one per side.
TEST(Stm, SheetNodesGetPlanarCharts) {
  const Mesh mesh = shapes::box(2.0f, 1.0f, 0.2f, 8);
  sk::Skeleton s;
  s.nodes.push_back({{0, 0, 0}, 0.1f, {}, true});
  for (std::uint32_t v = 0; v < mesh.positions.size(); ++v) s.nodes[0].vertices.push_back(v);
  const dif::Stm stm = dif::build_stm(mesh, s);
  test::expect_valid_stm(mesh, stm);
  EXPECT_EQ(stm.quality.sheet_charts, 6u);
  EXPECT_EQ(stm.quality.bone_charts, 0u);
  // Each side is flat and projected along its normal: an isometry.
  EXPECT_NEAR(stm.quality.area_distortion.max, 1.0, 1e-3);
  EXPECT_NEAR(stm.quality.angle_distortion.max, 1.0, 1e-3);
}

// Vertices no node holds take a neighbour's node.
TEST(Stm, UnassignedVerticesTakeANeighboursNode) {
  const Mesh mesh = capsule();
  sk::Skeleton s = capsule_skeleton(mesh);
  s.nodes[2].vertices.resize(s.nodes[2].vertices.size() / 2);
  const dif::Stm stm = dif::build_stm(mesh, s);
  test::expect_valid_stm(mesh, stm);
}

TEST(Stm, BadInputIsRefused) {
  const Mesh mesh = capsule();
  sk::Skeleton s = capsule_skeleton(mesh);
  EXPECT_THROW(dif::build_stm(mesh, sk::Skeleton{}), InputError);
  EXPECT_THROW(dif::build_stm(Mesh{}, s), InputError);
  sk::Skeleton bad = s;
  bad.nodes[0].vertices.push_back(static_cast<std::uint32_t>(mesh.positions.size()));
  EXPECT_THROW(dif::build_stm(mesh, bad), InputError);
  bad = s;
  bad.edges.push_back({0, 99});
  EXPECT_THROW(dif::build_stm(mesh, bad), InputError);
  dif::StmOptions o;
  o.atlas_size = 8;
  EXPECT_THROW(dif::build_stm(mesh, s, o), UsageError);
  o = {};
  o.gutter = 65;
  EXPECT_THROW(dif::build_stm(mesh, s, o), UsageError);
  o = {};
  o.max_stretch = 0.5;
  EXPECT_THROW(dif::build_stm(mesh, s, o), UsageError);
}

TEST(Stm, TooManyChartsForTheAtlasIsAnError) {
  // 30 separate boxes of sheet nodes: 180 charts of at least one texel plus a gutter of 2 do not
  // fit 16² (at most 4 × 4).
  Mesh mesh;
  for (int i = 0; i < 30; ++i) {
    const Mesh b = shapes::box(1.0f, 1.0f, 1.0f, 2);
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    for (const glm::vec3& p : b.positions) mesh.positions.push_back(p + glm::vec3(2.0f * static_cast<float>(i), 0, 0));
    for (const Triangle& t : b.triangles) mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  sk::Skeleton s;
  s.nodes.push_back({{0, 0, 0}, 0.5f, {}, true});
  dif::StmOptions o;
  o.atlas_size = 16;
  o.gutter = 2;
  EXPECT_THROW(dif::build_stm(mesh, s, o), InputError);
  o.atlas_size = 256;
  test::expect_valid_stm(mesh, dif::build_stm(mesh, s, o), o);
}

TEST(Stm, SkeletonJsonRoundTrips) {
  const Mesh mesh = capsule();
  const sk::Skeleton s = capsule_skeleton(mesh);
  const sk::Skeleton r = dif::parse_skeleton_json(sk::to_json(s), "test");
  ASSERT_EQ(r.nodes.size(), s.nodes.size());
  for (std::size_t i = 0; i < s.nodes.size(); ++i) {
    EXPECT_EQ(r.nodes[i].position, s.nodes[i].position);
    EXPECT_EQ(r.nodes[i].vertices, s.nodes[i].vertices);
    EXPECT_EQ(r.nodes[i].sheet, s.nodes[i].sheet);
  }
  EXPECT_EQ(r.edges, s.edges);
  const dif::Stm a = dif::build_stm(mesh, s), b = dif::build_stm(mesh, r);
  EXPECT_EQ(a.mapping.vertex_chart, b.mapping.vertex_chart);
}

TEST(Stm, MalformedSkeletonJsonIsOneInputError) {
  EXPECT_THROW(dif::parse_skeleton_json("{", "x"), InputError);
  EXPECT_THROW(dif::parse_skeleton_json("[]", "x"), InputError);
  EXPECT_THROW(dif::parse_skeleton_json(R"({"nodes":[{"position":[0,0]}]})", "x"), InputError);
  EXPECT_THROW(dif::parse_skeleton_json(R"({"nodes":[{"position":[0,0,0]}],"edges":[[0,1]]})", "x"), InputError);
  EXPECT_THROW(dif::parse_skeleton_json(R"({"nodes":[{"position":[0,0,0],"vertices":[-1]}]})", "x"), InputError);
  EXPECT_THROW(dif::read_skeleton_json("/nonexistent/skeleton.json"), InputError);
}

TEST(Stm, AtlasPngHasTheAtlasSizeAndRefusesWrongValues) {
  const Mesh mesh = capsule();
  dif::StmOptions o;
  o.atlas_size = 256;
  const dif::Stm stm = dif::build_stm(mesh, capsule_skeleton(mesh), o);
  test::ScratchDir dir;
  std::vector<float> z(mesh.positions.size());
  for (std::size_t v = 0; v < z.size(); ++v) z[v] = mesh.positions[v].z;
  const std::string path = dir.path("atlas.png");
  dif::write_atlas_png(stm.mapping, mesh, z, path);
  std::ifstream in(path, std::ios::binary);
  unsigned char head[24] = {};
  in.read(reinterpret_cast<char*>(head), 24);
  ASSERT_TRUE(in.good());
  EXPECT_EQ(0, std::memcmp(head, "\x89PNG\r\n\x1a\n", 8));
  const auto be32 = [&](int at) { return (head[at] << 24) | (head[at + 1] << 16) | (head[at + 2] << 8) | head[at + 3]; };
  EXPECT_EQ(be32(16), 256);
  EXPECT_EQ(be32(20), 256);
  const std::string bad = dir.path("bad.png");
  EXPECT_THROW(dif::write_atlas_png(stm.mapping, mesh, std::vector<float>(3, 0.0f), bad), InputError);
  EXPECT_FALSE(std::filesystem::exists(bad));
}

// keep_reads_that_see_the_vertex on a mapping made by hand: two flat 9 × 9 grids A and B (apart in
// space: x in [0, 8] and [20, 28]) drawn by one chart with B one texel to the right of A, 2 texels
// per grid step: a tear. A's last column reads texels B draws; its reads are dropped and it reads
// where A's nearest clean vertices read, never at B; no read crosses the tear either way; vertices
// further than 3 texels from it keep their own read alone. With B in a chart of its own, far from
// A, nothing is dropped.
TEST(Stm, AReadThatSeesAnotherPartOfTheSurfaceIsDropped) {
  constexpr std::uint32_t n = 9;
  Mesh mesh;
  for (int piece = 0; piece < 2; ++piece)
    for (std::uint32_t j = 0; j < n; ++j)
      for (std::uint32_t i = 0; i < n; ++i) mesh.positions.push_back({float(i) + 20.0f * float(piece), float(j), 0.0f});
  const auto id = [&](int piece, std::uint32_t i, std::uint32_t j) { return static_cast<std::uint32_t>(piece) * n * n + j * n + i; };
  for (int piece = 0; piece < 2; ++piece)
    for (std::uint32_t j = 0; j + 1 < n; ++j)
      for (std::uint32_t i = 0; i + 1 < n; ++i) {
        mesh.triangles.push_back({id(piece, i, j), id(piece, i + 1, j), id(piece, i + 1, j + 1)});
        mesh.triangles.push_back({id(piece, i, j), id(piece, i + 1, j + 1), id(piece, i, j + 1)});
      }
  const std::uint32_t V = mesh.vertex_count();
  // A's x in texels: 2.25 + 2 i (its last column at 18.25); B's starts one texel to the right.
  const float a_last = 2.25f + 2.0f * (n - 1), b_first = a_last + 1.0f;
  const auto make = [&](bool torn) {
    dif::AtlasMapping m;
    m.size = 128;
    m.gutter = 1;
    m.charts.push_back({dif::Chart::Kind::Joint, 1, 1, 60, 20, false, 0.5f});
    if (!torn) m.charts.push_back({dif::Chart::Kind::Joint, 1, 40, 60, 20, false, 0.5f});
    const auto uv = [&](std::uint32_t v) {
      const int piece = v >= n * n ? 1 : 0;
      const std::uint32_t i = (v % (n * n)) % n, j = (v % (n * n)) / n;
      const float x = piece == 0 ? 2.25f + 2.0f * float(i) : (torn ? b_first : 2.25f) + 2.0f * float(i);
      const float y = 2.25f + 2.0f * float(j) + (piece == 1 && !torn ? 39.0f : 0.0f);
      return glm::vec2(x, y);
    };
    for (std::uint32_t f = 0; f < mesh.face_count(); ++f) {
      const Triangle& t = mesh.triangles[f];
      m.triangles.push_back({t[0] >= n * n && !torn ? 1u : 0u, f, {uv(t[0]), uv(t[1]), uv(t[2])}});
    }
    for (std::uint32_t v = 0; v < V; ++v) {
      m.vertex_chart.push_back(v >= n * n && !torn ? 1u : 0u);
      m.vertex_uv.push_back(uv(v));
      m.samples.push_back({v, m.vertex_chart.back(), uv(v), 1.0f});
    }
    return m;
  };
  dif::AtlasMapping m = make(true);
  const dif::AtlasMapping before = m;
  const dif::ReadCheck check = dif::keep_reads_that_see_the_vertex(mesh, m);
  std::vector<std::vector<dif::VertexSample>> reads(V);
  for (std::size_t k = 0; k < m.samples.size(); ++k) {
    if (k > 0) {
      ASSERT_LE(m.samples[k - 1].vertex, m.samples[k].vertex) << "sorted by vertex";
    }
    reads[m.samples[k].vertex].push_back(m.samples[k]);
  }
  std::size_t dropped = 0;
  for (std::uint32_t v = 0; v < V; ++v) {
    ASSERT_FALSE(reads[v].empty()) << v;
    const bool in_a = v < n * n;
    const float x = before.vertex_uv[v].x;
    for (const dif::VertexSample& s : reads[v]) {
      EXPECT_EQ(s.uv.x <= a_last, in_a) << "vertex " << v << " reads across the tear at " << s.uv.x;
      EXPECT_GT(s.weight, 0.0f);
    }
    const bool own = reads[v].size() == 1 && reads[v][0].uv == before.vertex_uv[v];
    if (std::abs(x - (a_last + 0.5f)) > 3.0f) {
      EXPECT_TRUE(own) << "vertex " << v << " at " << x << " is far from the tear";
    }
    if (x == a_last || x == b_first) {
      EXPECT_FALSE(own) << "vertex " << v << " at " << x << " reads texels of the other grid";
    }
    dropped += own ? 0 : 1;
  }
  EXPECT_EQ(check.dropped_own, dropped);
  EXPECT_EQ(check.borrowed, dropped) << "one chart: a dropped read leaves no other";
  EXPECT_GE(dropped, 2u * n);
  dif::AtlasMapping apart = make(false);
  const std::vector<dif::VertexSample> kept = apart.samples;
  const dif::ReadCheck none = dif::keep_reads_that_see_the_vertex(mesh, apart);
  EXPECT_EQ(none.dropped_own, 0u);
  EXPECT_EQ(none.borrowed, 0u);
  ASSERT_EQ(apart.samples.size(), kept.size());
  for (std::size_t k = 0; k < kept.size(); ++k) EXPECT_EQ(apart.samples[k].uv, kept[k].uv);
  // A mapping that does not fit the mesh is an input error, not a read out of bounds.
  dif::AtlasMapping bad = make(true);
  bad.samples.back().vertex = V;
  EXPECT_THROW(dif::keep_reads_that_see_the_vertex(mesh, bad), InputError);
  bad = make(true);
  bad.triangles.back().face = static_cast<std::uint32_t>(mesh.face_count());
  EXPECT_THROW(dif::keep_reads_that_see_the_vertex(mesh, bad), InputError);
  bad = make(true);
  bad.vertex_chart.pop_back();
  EXPECT_THROW(dif::keep_reads_that_see_the_vertex(mesh, bad), InputError);
  bad = make(true);
  std::swap(bad.samples.front(), bad.samples.back());
  EXPECT_THROW(dif::keep_reads_that_see_the_vertex(mesh, bad), InputError);
  bad = make(true);
  bad.charts[0].width = 0;
  EXPECT_THROW(dif::keep_reads_that_see_the_vertex(mesh, bad), InputError);
  // A read at no texel (a NaN uv) is dropped like one that sees another part of the surface.
  bad = make(true);
  bad.samples[0].uv.x = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(dif::keep_reads_that_see_the_vertex(mesh, bad).dropped_own, dropped + 1);
  // No samples (no blended read-back): nothing to check, nothing changed.
  bad = make(true);
  bad.samples.clear();
  EXPECT_EQ(dif::keep_reads_that_see_the_vertex(mesh, bad).dropped_own, 0u);
  EXPECT_TRUE(bad.samples.empty());
}

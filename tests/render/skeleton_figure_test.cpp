// Readable skeleton and point-cloud pictures, checked on pixels (lavapipe in CI, validation on):
// the orientation rule, tight framing (the drawn object's pixel box fills each view), skeleton
// parts in their own colours on a model with a known skeleton, point frames and strips.

#include "../vulkan/vk_test_util.hpp"

#include "analytic.hpp"

#include "sdfkit/core/shapes.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/render/figure.hpp"
#include "sdfkit/skeleton/models.hpp"
#include "scratch.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>

namespace sdfkit::render {
namespace {

constexpr std::array<std::uint8_t, 3> kWhite{255, 255, 255};

std::size_t count_color(const Image& img, std::array<std::uint8_t, 3> c, int x0 = 0, int x1 = -1) {
  if (x1 < 0) x1 = img.width;
  std::size_t n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = x0; x < x1; ++x) {
      const std::uint8_t* p = img.pixel(x, y);
      n += p[0] == c[0] && p[1] == c[1] && p[2] == c[2];
    }
  return n;
}

// Share of the view the drawn pixels' box fills along its fuller side.
double fill_share(const Image& img, const SceneView& v) {
  const std::array<int, 4> b = drawn_box(img, v, kWhite);
  return std::max(static_cast<double>(b[2] - b[0]) / v.width, static_cast<double>(b[3] - b[1]) / v.height);
}

// ---- Without a device ------------------------------------------------------------------------

TEST(Orientation, LongestAxisIsUpForMeshFilesAndPlusYForGltf) {
  EXPECT_EQ(up_rule_for("a/b/man.off"), UpRule::LongestAxis);
  EXPECT_EQ(up_rule_for("x.OBJ"), UpRule::LongestAxis);
  EXPECT_EQ(up_rule_for("x.ply"), UpRule::LongestAxis);
  EXPECT_EQ(up_rule_for("x.glb"), UpRule::PlusY);
  EXPECT_EQ(up_rule_for("x.GLTF"), UpRule::PlusY);
  const glm::vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int long_axis = 0; long_axis < 3; ++long_axis) {
    // Sizes: 4 along the long axis, 1.5 and 1 along the others: front is the shortest.
    glm::vec3 size(1.0f);
    size[long_axis] = 4.0f;
    const int mid = (long_axis + 1) % 3, short_axis = (long_axis + 2) % 3;
    size[mid] = 1.5f;
    const Mesh box = shapes::box(size.x, size.y, size.z, 1);
    const Orientation o = orient(box.positions, UpRule::LongestAxis);
    EXPECT_EQ(o.up, axes[long_axis]) << long_axis;
    EXPECT_EQ(o.front, axes[short_axis]) << long_axis;
    const Orientation g = orient(box.positions, UpRule::PlusY);  // glTF: +Y whatever the shape
    EXPECT_EQ(g.up, glm::vec3(0, 1, 0));
    EXPECT_EQ(g.front, glm::vec3(0, 0, 1));
  }
  const Mesh cube = shapes::box(1, 1, 1, 1);  // ties: y up, then z front
  EXPECT_EQ(orient(cube.positions, UpRule::LongestAxis).up, glm::vec3(0, 1, 0));
  EXPECT_EQ(orient(cube.positions, UpRule::LongestAxis).front, glm::vec3(0, 0, 1));
  const Mesh flat = shapes::box(4, 1, 2, 1);
  const Orientation down = orientation_with_up(flat.positions, "-z");
  EXPECT_EQ(down.up, glm::vec3(0, 0, -1));
  EXPECT_EQ(down.front, glm::vec3(0, 1, 0));
  EXPECT_THROW(orientation_with_up(flat.positions, "w"), InputError);
  EXPECT_THROW(orientation_with_up(flat.positions, "+xy"), InputError);
}

TEST(SkeletonParts, LeavesBranchesAndSheetNodesByDegree) {
  SkeletonOverlay s;
  for (int i = 0; i < 8; ++i) s.nodes.emplace_back(static_cast<float>(i), 0.0f, 0.0f);
  s.edges = {{0, 1}, {1, 2}, {1, 3}, {3, 4}, {4, 5}};  // 1 branches; 0, 2, 5 are leaves
  s.sheet_triangles = {{5, 6, 7}};                     // 5 touches a sheet: not a leaf
  const std::vector<SkeletonPart> p = node_parts(s);
  const std::vector<SkeletonPart> want{SkeletonPart::Leaf, SkeletonPart::Branch, SkeletonPart::Leaf,
                                       SkeletonPart::Node, SkeletonPart::Node, SkeletonPart::Node,
                                       SkeletonPart::Sheet, SkeletonPart::Sheet};
  EXPECT_EQ(p, want);
  s.ordered = true;
  EXPECT_EQ(node_parts(s)[0], SkeletonPart::First);
  // Every part has its own colour.
  std::map<std::array<std::uint8_t, 3>, int> colours;
  for (const SkeletonPart part : {SkeletonPart::Curve, SkeletonPart::Sheet, SkeletonPart::SheetOutline,
                                  SkeletonPart::Node, SkeletonPart::Branch, SkeletonPart::Leaf, SkeletonPart::First})
    ++colours[skeleton_color(part)];
  EXPECT_EQ(colours.size(), 7u);
  s.edges.push_back({2, 9});
  EXPECT_THROW(node_parts(s), InputError);
}

TEST(SkeletonFile, MeshSkeletonsPolylinesAndFrames) {
  const sdfkit::test::ScratchDir scratch;  // unique per run: two trees may run the suite at once
  const auto dir = scratch.dir();
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream((dir / name).string()) << text;
    return (dir / name).string();
  };
  const auto mesh = read_skeleton_json(write(
      "m.json", R"({"nodes":[{"position":[0,0,0]},{"position":[1,0,0]},{"position":[0,1,0]}],"edges":[[0,1]],"sheet_triangles":[[0,1,2]]})"));
  ASSERT_EQ(mesh.size(), 1u);
  EXPECT_FALSE(mesh[0].ordered);
  EXPECT_EQ(mesh[0].edges.size(), 1u);
  EXPECT_EQ(mesh[0].sheet_triangles.size(), 1u);
  const auto line = read_skeleton_json(
      write("p.json", R"({"nodes":[{"position":[0,0,0],"radius":1},{"position":[1,0,0]},{"position":[2,0,0]}]})"));
  ASSERT_EQ(line.size(), 1u);
  EXPECT_TRUE(line[0].ordered);
  ASSERT_EQ(line[0].edges.size(), 2u);
  EXPECT_EQ(line[0].edges[1], (std::array<std::uint32_t, 2>{1, 2}));
  const auto frames = read_skeleton_json(
      write("f.json", R"({"frames":[{"nodes":[{"position":[0,0,0]},{"position":[1,0,0]}]},{"nodes":[{"position":[0,0,1]},{"position":[1,0,1]}]}]})"));
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[1].nodes[0].z, 1.0f);
  EXPECT_THROW(read_skeleton_json(write("b1.json", "[1,2]")), InputError);
  EXPECT_THROW(read_skeleton_json(write("b2.json", R"({"nodes":[{"position":[0,0]}]})")), InputError);
  EXPECT_THROW(read_skeleton_json(write("b3.json", R"({"nodes":[{"position":[0,0,0]}],"edges":[[0,3]]})")), InputError);
  EXPECT_THROW(read_skeleton_json(write("b4.json", R"({"frames":[]})")), InputError);
  EXPECT_THROW(read_skeleton_json(write("b5.json", "{")), InputError);
  EXPECT_THROW(read_skeleton_json((dir / "missing.json").string()), InputError);
  std::filesystem::remove_all(dir);
}

// ---- On the device -----------------------------------------------------------------------------

using SkeletonPicture = test::DeviceTest;

// Boxes 1 x 1.5 x 5 along each axis, drawn by the longest-axis rule in 4 views: the box stands
// in every view (its pixel box is taller than wide) and fills at least 90 % of each view's
// height; every view is centred on it. The bounding-sphere framing this replaced left a box lying
// along x at a fifth of the view's height.
TEST_F(SkeletonPicture, ElongatedBoxesStandUpAndFillEveryView) {
  for (int long_axis = 0; long_axis < 3; ++long_axis) {
    glm::vec3 size(1.0f);
    size[long_axis] = 5.0f;
    size[(long_axis + 1) % 3] = 1.5f;
    const Mesh box = shapes::box(size.x, size.y, size.z, 2);
    RenderOptions o;
    o.views = 4;
    o.width = 640;
    o.height = 360;
    o.histogram = o.colorbar = false;
    o.setup.orientation = orient(box.positions, UpRule::LongestAxis);
    const std::vector<float> values(box.vertex_count(), 0.5f);
    const Image img = render_figure(*ctx_, box, values, SdfDomain::Vertex, o);
    const std::vector<SceneView> views = orbit_views(box.positions, 4, o.width, o.height, o.setup);
    ASSERT_EQ(views.size(), 4u);
    for (const SceneView& v : views) {
      const std::array<int, 4> b = drawn_box(img, v, kWhite);
      const int w = b[2] - b[0], h = b[3] - b[1];
      EXPECT_GT(h, 2 * w) << "axis " << long_axis;
      EXPECT_GE(static_cast<double>(h) / v.height, 0.90) << "axis " << long_axis;
      EXPECT_GE(fill_share(img, v), 0.90);
      EXPECT_NEAR(0.5 * (b[0] + b[2]), 0.5 * v.width, 2.0) << "axis " << long_axis;
      EXPECT_NEAR(0.5 * (b[1] + b[3]), 0.5 * v.height, 2.0) << "axis " << long_axis;
    }
  }
}

// CGAL meshes (a human, quadrupeds, the elephant, a knot, the armadillo, the bunny) drawn by the
// rule in 3 views at one common scale: in every view the drawn pixels' box is the projection of
// the vertices (computed here from the view's matrix) within 2 px, centred in the view; the
// fullest view fills >= 90 % of its cell along its limiting side, and the others are at the same
// scale (so a narrow view of a wide animal fills less).
TEST_F(SkeletonPicture, RealMeshesAreFramedByTheirProjection) {
  for (const char* name : {"man.off", "camel.off", "elephant.off", "cow.off", "knot2.off", "armadillo.off",
                           "bunny00.off", "diplodocus.off"}) {
    const io::Asset a = io::load_asset(test::data_mesh(name));
    RenderOptions o;
    o.views = 3;
    o.width = 1200;
    o.height = 400;
    o.histogram = o.colorbar = false;
    o.setup.orientation = orient(a.mesh.positions, UpRule::LongestAxis);
    const std::vector<float> values(a.mesh.vertex_count(), 0.5f);
    const Image img = render_figure(*ctx_, a.mesh, values, SdfDomain::Vertex, o);
    const std::vector<SceneView> views = orbit_views(a.mesh.positions, 3, o.width, o.height, o.setup);
    double fullest = 0.0;
    for (const SceneView& v : views) {
      float x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
      for (const glm::vec3& p : a.mesh.positions) {
        const glm::vec4 c = v.view_projection * glm::vec4(p, 1.0f);
        const float px = (0.5f * c.x / c.w + 0.5f) * static_cast<float>(v.width);
        const float py = (0.5f * c.y / c.w + 0.5f) * static_cast<float>(v.height);
        x0 = std::min(x0, px);
        x1 = std::max(x1, px);
        y0 = std::min(y0, py);
        y1 = std::max(y1, py);
      }
      const std::array<int, 4> b = drawn_box(img, v, kWhite);
      EXPECT_NEAR(b[0], x0, 2.0) << name;
      EXPECT_NEAR(b[2], x1, 2.0) << name;
      EXPECT_NEAR(b[1], y0, 2.0) << name;
      EXPECT_NEAR(b[3], y1, 2.0) << name;
      EXPECT_NEAR(0.5 * (b[0] + b[2]), 0.5 * v.width, 2.0) << name;
      EXPECT_NEAR(0.5 * (b[1] + b[3]), 0.5 * v.height, 2.0) << name;
      fullest = std::max(fullest, fill_share(img, v));
    }
    // 400 x 400 cells: the border is 3 % + 8 px a side, so the object fills up to 90 %.
    const double border = 2.0 * (0.03 * 400 + 8.0) / 400.0;
    EXPECT_GE(fullest, 1.0 - border - 0.01) << name;
    EXPECT_NEAR(1.0 - border, 0.90, 1e-9);
  }
}

// The five-armed star (a procedural model whose medial axis is known: five segments from the
// centre) with its skeleton: a branch node at the centre, two curve nodes and a leaf per arm, and
// a sheet of two triangles. Each part shows in its own colour with the pixel count its size
// gives: leaves 10 x 10 px squares drawn over everything, the branch 8 x 8, curve nodes 6 x 6,
// the sheet filling its projected area. The faded mesh alone never takes any of these colours.
TEST_F(SkeletonPicture, CurvesSheetsAndLeavesInTheirOwnColours) {
  const skeleton::models::Star star = skeleton::models::five_armed_star();
  SkeletonOverlay s;
  s.nodes.push_back(glm::vec3(0.0f));
  for (const auto& arm : star.axis) {
    const std::uint32_t base = static_cast<std::uint32_t>(s.nodes.size());
    for (int k = 1; k <= 3; ++k) s.nodes.push_back(arm[0] + (arm[1] - arm[0]) * (static_cast<float>(k) / 3.0f));
    s.edges.push_back({0, base});
    s.edges.push_back({base, base + 1});
    s.edges.push_back({base + 1, base + 2});
  }
  // A sheet: a 0.6 x 0.6 square in the star's plane between arms 0 and 1, away from the curves.
  const glm::vec3 c = 1.1f * glm::normalize(star.axis[0][1] + star.axis[1][1]);
  const std::uint32_t q = static_cast<std::uint32_t>(s.nodes.size());
  for (const glm::vec2 d : {glm::vec2(-0.3f, -0.3f), glm::vec2(0.3f, -0.3f), glm::vec2(0.3f, 0.3f), glm::vec2(-0.3f, 0.3f)})
    s.nodes.push_back(c + glm::vec3(d, 0.0f));
  s.sheet_triangles = {{q, q + 1, q + 2}, {q, q + 2, q + 3}};

  RenderOptions o;
  o.views = 1;
  o.width = o.height = 400;
  o.histogram = o.colorbar = false;
  o.fade = 0.55f;
  o.setup.orientation = orient(star.mesh.positions, UpRule::LongestAxis);
  o.setup.elevation_degrees = 0.0f;  // looking at the star's plane face on: no arm hides another
  o.setup.azimuth_degrees = 0.0f;
  ASSERT_NEAR(std::abs(o.setup.orientation.front.z), 1.0f, 1e-6f);
  const std::vector<float> values(star.mesh.vertex_count(), 0.3f);
  const Image plain = render_figure(*ctx_, star.mesh, values, SdfDomain::Vertex, o);
  for (const SkeletonPart part : {SkeletonPart::Curve, SkeletonPart::Sheet, SkeletonPart::SheetOutline,
                                  SkeletonPart::Node, SkeletonPart::Branch, SkeletonPart::Leaf, SkeletonPart::First})
    EXPECT_EQ(count_color(plain, skeleton_color(part)), 0u) << static_cast<int>(part);

  o.skeleton = s;
  const Image img = render_figure(*ctx_, star.mesh, values, SdfDomain::Vertex, o);
  const std::size_t leaves = count_color(img, skeleton_color(SkeletonPart::Leaf));
  const std::size_t branch = count_color(img, skeleton_color(SkeletonPart::Branch));
  const std::size_t nodes = count_color(img, skeleton_color(SkeletonPart::Node));
  const std::size_t curves = count_color(img, skeleton_color(SkeletonPart::Curve));
  const std::size_t sheet = count_color(img, skeleton_color(SkeletonPart::Sheet)) +
                            count_color(img, skeleton_color(SkeletonPart::SheetOutline));
  EXPECT_NEAR(static_cast<double>(leaves), 5 * 100.0, 5 * 12.0);
  EXPECT_NEAR(static_cast<double>(branch), 64.0, 12.0);
  EXPECT_NEAR(static_cast<double>(nodes), 10 * 36.0, 10 * 7.0);
  // Curves: 15 edges of 3 px width; arms 2 units long (minus what the nodes cover).
  const std::vector<SceneView> views = orbit_views(
      [&] {
        std::vector<glm::vec3> all = star.mesh.positions;
        all.insert(all.end(), s.nodes.begin(), s.nodes.end());
        return all;
      }(),
      1, o.width, o.height, o.setup);
  const double ppu = views[0].pixels_per_unit;
  EXPECT_GT(static_cast<double>(curves), 0.6 * 5 * 3 * (2.0 * ppu - 25.0));
  EXPECT_LT(static_cast<double>(curves), 1.2 * 5 * 3 * 2.0 * ppu);
  const double sheet_area = 0.36 * ppu * ppu;  // face on: the square's own area
  EXPECT_NEAR(static_cast<double>(sheet), sheet_area, 0.15 * sheet_area);
  // And framed tightly with the skeleton on.
  EXPECT_GE(fill_share(img, views[0]), 0.90);
}

// A tube-shaped point cloud along x with its polyline (5 nodes): the points, the curve, the
// three inner nodes, the last node as a leaf and the first node marked; tight framing, long axis up.
PointFrame tube_frame(float length, float bend, std::uint32_t seed) {
  PointFrame f;
  std::uint32_t state = seed;
  const auto rnd = [&] {
    state = state * 1664525u + 1013904223u;
    return static_cast<float>(state >> 8) / static_cast<float>(1u << 24);
  };
  const auto axis = [&](float t) { return glm::vec3(t * length, 0.0f, bend * std::sin(std::numbers::pi_v<float> * t)); };
  for (int i = 0; i < 1500; ++i) {
    const float t = rnd(), a = 2.0f * std::numbers::pi_v<float> * rnd();
    f.points.push_back(axis(t) + glm::vec3(0.0f, std::cos(a), std::sin(a)) * 1.5f);
  }
  for (int k = 0; k <= 4; ++k) f.skeleton.nodes.push_back(axis(static_cast<float>(k) / 4.0f));
  for (std::uint32_t k = 0; k < 4; ++k) f.skeleton.edges.push_back({k, k + 1});
  f.skeleton.ordered = true;
  return f;
}

RenderOptions point_options(int width, int height) {
  RenderOptions o;
  o.views = 1;
  o.width = width;
  o.height = height;
  o.histogram = o.colorbar = false;
  o.setup.elevation_degrees = 0.0f;
  o.setup.azimuth_degrees = 0.0f;
  return o;
}

TEST_F(SkeletonPicture, PointFrameShowsPointsPolylineAndNodes) {
  const PointFrame f = tube_frame(30.0f, 4.0f, 7);
  RenderOptions o = point_options(240, 400);
  o.setup.orientation = orient(f.points, UpRule::LongestAxis);
  EXPECT_EQ(o.setup.orientation.up, glm::vec3(1, 0, 0));
  const Image img = render_points_figure(*ctx_, f, o);
  EXPECT_NEAR(static_cast<double>(count_color(img, skeleton_color(SkeletonPart::First))), 144.0, 20.0);
  EXPECT_NEAR(static_cast<double>(count_color(img, skeleton_color(SkeletonPart::Leaf))), 100.0, 15.0);
  EXPECT_NEAR(static_cast<double>(count_color(img, skeleton_color(SkeletonPart::Node))), 3 * 36.0, 15.0);
  EXPECT_GT(count_color(img, skeleton_color(SkeletonPart::Curve)), 3u * 150u);
  // Points: drawn pixels that are neither background nor skeleton cover much of the tube.
  std::size_t points = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const std::uint8_t* p = img.pixel(x, y);
      points += p[2] > p[0] + 10 && p[2] < p[0] + 40 && p[0] > 90;  // the grey-blue sprites
    }
  EXPECT_GT(points, 3000u);  // about half the tube's 30 x 3 unit silhouette at ~7.5 px a unit
  const std::vector<SceneView> views = orbit_views(f.points, 1, o.width, o.height, o.setup);
  const std::array<int, 4> b = drawn_box(img, views[0], kWhite);
  EXPECT_GT(b[3] - b[1], 2 * (b[2] - b[0]));  // the tube stands
  EXPECT_GE(fill_share(img, views[0]), 0.90);
}

// A strip of four frames: one panel each, same scale (a tube half as long is drawn half as
// tall), each with its own first-node marker, labels under the panels.
TEST_F(SkeletonPicture, StripHasOnePanelPerFrameAtOneScale) {
  std::vector<PointFrame> frames{tube_frame(30.0f, 3.0f, 1), tube_frame(30.0f, -3.0f, 2), tube_frame(15.0f, 0.0f, 3),
                                 tube_frame(30.0f, 6.0f, 4)};
  for (std::size_t i = 0; i < frames.size(); ++i) frames[i].label = std::to_string(10 * i);
  RenderOptions o = point_options(480, 320);
  std::vector<glm::vec3> all;
  for (const PointFrame& f : frames) all.insert(all.end(), f.points.begin(), f.points.end());
  o.setup.orientation = orient(all, UpRule::LongestAxis);
  const Image img = render_strip(*ctx_, frames, o);
  ASSERT_EQ(img.width, 480);
  ASSERT_EQ(img.height, 320);
  std::vector<int> heights;
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(static_cast<double>(count_color(img, skeleton_color(SkeletonPart::First), i * 120 + 1, (i + 1) * 120)),
                144.0, 20.0)
        << "panel " << i;
    SceneView panel;
    panel.x = i * 120 + 1;
    panel.y = 0;
    panel.width = 119;
    panel.height = 280;  // above the labels
    const std::array<int, 4> b = drawn_box(img, panel, kWhite);
    ASSERT_GT(b[3], b[1]) << "panel " << i << " is empty";
    heights.push_back(b[3] - b[1]);
  }
  // Heights without the end markers (the first node's 12 px and the leaf's 10 px squares, half
  // of each beyond the tube's ends).
  EXPECT_NEAR((heights[2] - 11.0) / (heights[0] - 11.0), 0.5, 0.04);
  EXPECT_GE(*std::max_element(heights.begin(), heights.end()), 0.85 * 280);
  // Labels: dark pixels below the panels.
  SceneView labels;
  labels.x = 0;
  labels.y = 290;
  labels.width = 480;
  labels.height = 30;
  EXPECT_GT(drawn_box(img, labels, kWhite)[2], 360);  // the last panel's label too

  std::vector<PointFrame> none;
  EXPECT_THROW(render_strip(*ctx_, none, o), InputError);
  std::vector<PointFrame> empty(2);
  EXPECT_THROW(render_strip(*ctx_, empty, o), InputError);
  RenderOptions narrow = o;
  narrow.width = 64;
  EXPECT_THROW(render_strip(*ctx_, std::vector<PointFrame>(8, frames[0]), narrow), InputError);
  RenderOptions with_values = o;
  with_values.histogram = true;
  EXPECT_THROW(render_points_figure(*ctx_, frames[0], with_values), InputError);
  PointFrame broken = frames[0];
  broken.skeleton.edges.push_back({0, 99});
  EXPECT_THROW(render_points_figure(*ctx_, broken, o), InputError);
}

}  // namespace
}  // namespace sdfkit::render

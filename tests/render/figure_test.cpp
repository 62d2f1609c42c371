// Headless figure rendering on a real device (lavapipe in CI) with validation on: image size,
// coverage against the orthographic camera's analytic projected area, colours against
// io::colormap, flat per-face colours, the skeleton overlay, histogram and colour bar, PNG.

#include "../vulkan/vk_test_util.hpp"

#include "sdfkit/core/shapes.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/render/figure.hpp"
#include "scratch.hpp"

#include <filesystem>
#include <fstream>
#include <numbers>

namespace sdfkit::render {
namespace {

bool is_background(const std::uint8_t* p) { return p[0] == 255 && p[1] == 255 && p[2] == 255; }

std::size_t covered(const Image& img) {
  std::size_t n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) n += is_background(img.pixel(x, y)) ? 0 : 1;
  return n;
}

using Render = test::DeviceTest;

// One orthographic view of a sphere of radius R covers pi (R * pixels_per_unit)^2 pixels.
TEST_F(Render, SphereCoversItsProjectedDisc) {
  const Mesh sphere = shapes::icosphere(1.0f, 4);
  const std::vector<float> values(sphere.vertex_count(), 1.0f);
  MeshRenderer r(*ctx_);
  r.set_mesh(sphere, values, SdfDomain::Vertex, sdf_scale(0.0f, 2.0f));
  const std::vector<SceneView> views = orbit_views(sphere, 1, 240, 180);
  ASSERT_EQ(views.size(), 1u);
  const Image img = r.render(240, 180, views);
  ASSERT_EQ(img.width, 240);
  ASSERT_EQ(img.height, 180);
  const double radius_px = views[0].pixels_per_unit;  // icosphere vertices lie on R = 1
  const double expected = std::numbers::pi * radius_px * radius_px;
  EXPECT_NEAR(static_cast<double>(covered(img)), expected, 0.03 * expected);
  // The disc is centred in the view.
  EXPECT_FALSE(is_background(img.pixel(120, 90)));
  EXPECT_TRUE(is_background(img.pixel(2, 2)));
}

// A constant field is one hue: io::colormap(0.125) = (1, 0.5, 0) times the shading.
TEST_F(Render, ConstantFieldIsOneHueOfTheColourMap) {
  const Mesh sphere = shapes::icosphere(1.0f, 3);
  const std::vector<float> values(sphere.vertex_count(), 0.25f);
  RenderOptions o;
  o.views = 3;
  o.width = 300;
  o.height = 120;
  o.histogram = o.colorbar = false;
  o.lo = 0.0f;
  o.hi = 2.0f;
  const Image img = render_figure(*ctx_, sphere, values, SdfDomain::Vertex, o);
  ASSERT_EQ(img.width, 300);
  ASSERT_EQ(img.height, 120);
  const glm::vec3 c = io::colormap(0.125f);
  ASSERT_NEAR(c.y / c.x, 0.5f, 1e-6f);
  std::size_t mesh_pixels = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const std::uint8_t* p = img.pixel(x, y);
      if (is_background(p)) continue;
      ++mesh_pixels;
      ASSERT_EQ(p[2], 0) << x << "," << y;
      ASSERT_GT(p[0], 40) << x << "," << y;  // shading never goes below 30 %
      ASSERT_NEAR(static_cast<double>(p[1]) / p[0], 0.5, 2.0 / p[0]) << x << "," << y;
      ASSERT_EQ(p[3], 255);
    }
  EXPECT_GT(mesh_pixels, 3u * 1000u);  // three discs of radius ~ 34 px
}

// Per-face values give flat colours: a box whose +x faces are 0 (red) and the rest 1 (blue)
// shows red and blue but never the colour map's green between them; per-vertex values blend.
TEST_F(Render, PerFaceValuesAreFlat) {
  const Mesh cube = shapes::box(1.0f, 1.0f, 1.0f, 2);
  const std::vector<glm::vec3> n = face_normals(cube);
  std::vector<float> per_face(cube.face_count());
  for (std::size_t f = 0; f < per_face.size(); ++f) per_face[f] = n[f].x > 0.5f ? 0.0f : 1.0f;
  RenderOptions o;
  o.views = 4;
  o.width = 256;
  o.height = 256;
  o.histogram = o.colorbar = false;
  const Image img = render_figure(*ctx_, cube, per_face, SdfDomain::Face, o);
  std::size_t red = 0, blue = 0, other = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const std::uint8_t* p = img.pixel(x, y);
      if (is_background(p)) continue;
      if (p[0] > 0 && p[1] == 0 && p[2] == 0) ++red;
      else if (p[2] > 0 && p[0] == 0 && p[1] == 0) ++blue;
      else ++other;
    }
  EXPECT_GT(red, 500u);
  EXPECT_GT(blue, 500u);
  EXPECT_EQ(other, 0u);

  // The same split per vertex: vertices on the x = +0.5 side are 0, and triangles between
  // blend through the colour map's green.
  std::vector<float> per_vertex(cube.vertex_count());
  for (std::size_t v = 0; v < per_vertex.size(); ++v) per_vertex[v] = cube.positions[v].x > 0.49f ? 0.0f : 1.0f;
  const Image blend = render_figure(*ctx_, cube, per_vertex, SdfDomain::Vertex, o);
  std::size_t green = 0;
  for (int y = 0; y < blend.height; ++y)
    for (int x = 0; x < blend.width; ++x) {
      const std::uint8_t* p = blend.pixel(x, y);
      if (!is_background(p) && p[1] > p[0] && p[1] > p[2]) ++green;
    }
  EXPECT_GT(green, 100u);
}

// The skeleton overlay is drawn on top of the mesh: a line through the sphere's centre.
TEST_F(Render, SkeletonOverlayIsOnTop) {
  const Mesh sphere = shapes::icosphere(1.0f, 3);
  const std::vector<float> values(sphere.vertex_count(), 1.0f);
  RenderOptions o;
  o.views = 1;
  o.width = 200;
  o.height = 200;
  o.histogram = o.colorbar = false;
  o.lines = {{glm::vec3(0, -0.8f, 0), glm::vec3(0, 0.8f, 0)}};
  o.points = {glm::vec3(0, 0.8f, 0)};
  const Image img = render_figure(*ctx_, sphere, values, SdfDomain::Vertex, o);
  const std::uint8_t* centre = img.pixel(100, 100);
  EXPECT_LT(centre[0], 30);  // the dark line, not the red mesh
  EXPECT_LT(centre[1], 30);
  o.lines.clear();
  o.points.clear();
  const Image plain = render_figure(*ctx_, sphere, values, SdfDomain::Vertex, o);
  EXPECT_GT(plain.pixel(100, 100)[0], 100);
}

// The strip under the views: a colour bar from colormap(0) (red) to colormap(1) (blue) and
// histogram bars; the PNG is written and starts with the PNG signature.
TEST_F(Render, FigureHasColourBarAndHistogramAndWritesPng) {
  const Mesh sphere = shapes::icosphere(1.0f, 3);
  std::vector<float> values(sphere.vertex_count());
  for (std::size_t v = 0; v < values.size(); ++v) values[v] = 1.0f + sphere.positions[v].y;  // 0..2
  RenderOptions o;
  o.views = 2;
  o.width = 400;
  o.height = 300;
  const Image img = render_figure(*ctx_, sphere, values, SdfDomain::Vertex, o);
  ASSERT_EQ(img.width, 400);
  ASSERT_EQ(img.height, 300);
  // Find the colour bar: a row whose left end is red and right end is blue.
  int bar_row = -1;
  for (int y = img.height - 1; y > img.height / 2 && bar_row < 0; --y) {
    const std::uint8_t* l = img.pixel(6, y);
    const std::uint8_t* r = img.pixel(img.width - 7, y);
    if (l[0] > 240 && l[1] < 20 && l[2] < 20 && r[2] > 240 && r[0] < 20 && r[1] < 20) bar_row = y;
  }
  ASSERT_GE(bar_row, 0) << "no colour bar found";
  const std::uint8_t* mid = img.pixel(img.width / 2, bar_row);
  EXPECT_GT(mid[1], 240);  // green in the middle
  // Histogram bars above the colour bar: coloured, non-white pixels.
  std::size_t bar_pixels = 0;
  for (int y = bar_row - img.height / 5; y < bar_row - 4; ++y)
    for (int x = 0; x < img.width; ++x) bar_pixels += is_background(img.pixel(x, y)) ? 0 : 1;
  EXPECT_GT(bar_pixels, 1000u);

  const sdfkit::test::ScratchDir scratch;  // unique per run: two trees may run the suite at once
  const auto path = scratch.dir() / "sdfkit_render_test.png";
  write_png(path.string(), img);
  std::ifstream f(path, std::ios::binary);
  char sig[8] = {};
  f.read(sig, 8);
  EXPECT_EQ(std::string(sig + 1, 3), "PNG");
  std::filesystem::remove(path);
}

TEST_F(Render, BadInputsAreErrors) {
  const Mesh sphere = shapes::icosphere(1.0f, 1);
  const std::vector<float> wrong(3, 1.0f);
  EXPECT_THROW(render_figure(*ctx_, sphere, wrong, SdfDomain::Vertex, {}), InputError);
  RenderOptions tiny;
  tiny.width = 10;
  const std::vector<float> ok(sphere.vertex_count(), 1.0f);
  EXPECT_THROW(render_figure(*ctx_, sphere, ok, SdfDomain::Vertex, tiny), InputError);
}

TEST(RenderText, DigitsHaveTheirWidth) {
  Image img;
  img.width = 64;
  img.height = 16;
  img.rgba.assign(64 * 16 * 4, 255);
  EXPECT_EQ(draw_text(img, 1, 1, "-1.5e+03", 1, {0, 0, 0}), 8 * 6 - 1);
  EXPECT_EQ(covered(img) > 20, true);
}

}  // namespace
}  // namespace sdfkit::render

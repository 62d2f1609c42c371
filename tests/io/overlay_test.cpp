// Overlays (a skeleton) written into glTF outputs as a node of their own.
#include "sdfkit/core/error.hpp"
#include "sdfkit/core/sdf.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/io/asset.hpp"
#include "scratch.hpp"

#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <filesystem>

namespace fs = std::filesystem;
using namespace sdfkit;

namespace {
io::Asset asset_of(const Mesh& m) {
  io::Asset a;
  a.path = "generated";
  a.format = io::Format::Off;
  a.input_positions = m.positions;
  a.input_triangles = m.triangles;
  a.mesh = m;
  for (std::uint32_t i = 0; i < m.positions.size(); ++i) a.input_to_welded.push_back(i);
  return a;
}

SdfField constant_field(const Mesh& m) {
  SdfField f;
  f.values.assign(m.positions.size(), 1.0f);
  f.kept_rays.assign(m.positions.size(), 1u);
  f.filled.assign(m.positions.size(), 0);
  return f;
}
}  // namespace

TEST(Overlay, SkeletonBecomesANodeWithLinesAndTriangles) {
  const Mesh m = shapes::capsule(0.5f, 3.0f, 16, 6);
  const SdfField f = constant_field(m);
  io::WriteOptions o;
  io::Overlay skel;
  skel.name = "skeleton";
  skel.points = {{0, 0, -1.5f}, {0, 0, 0}, {0, 0, 1.5f}, {0.2f, 0, 0}};
  skel.lines = {{0, 1}, {1, 2}};
  skel.triangles = {{1, 2, 3}};
  o.overlays.push_back(skel);
  const sdfkit::test::ScratchDir scratch;  // unique per run: two trees may run the suite at once
  const fs::path out = scratch.dir() / "sdfkit_overlay_test.glb";
  io::write_field(out.string(), asset_of(m), f, o);

  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, out.string())) << err;
  fs::remove(out);
  const auto& roots = model.scenes.at(static_cast<std::size_t>(model.defaultScene)).nodes;
  ASSERT_EQ(roots.size(), 2u);
  const tinygltf::Node& node = model.nodes.at(static_cast<std::size_t>(roots[1]));
  EXPECT_EQ(node.name, "skeleton");
  const tinygltf::Mesh& mesh = model.meshes.at(static_cast<std::size_t>(node.mesh));
  ASSERT_EQ(mesh.primitives.size(), 2u);
  EXPECT_EQ(mesh.primitives[0].mode, TINYGLTF_MODE_LINE);
  EXPECT_EQ(model.accessors.at(static_cast<std::size_t>(mesh.primitives[0].indices)).count, 4u);
  EXPECT_EQ(mesh.primitives[1].mode, TINYGLTF_MODE_TRIANGLES);
  EXPECT_EQ(model.accessors.at(static_cast<std::size_t>(mesh.primitives[1].indices)).count, 3u);
}

TEST(Overlay, ReadingTheFileBackTakesOnlyTheSurface) {
  const Mesh m = shapes::capsule(0.5f, 3.0f, 16, 6);
  const SdfField f = constant_field(m);
  io::WriteOptions o;
  io::Overlay skel;
  skel.name = "skeleton";
  skel.points = {{0, 0, -1.5f}, {0, 0, 1.5f}, {0.2f, 0, 0}};
  skel.lines = {{0, 1}};
  skel.triangles = {{0, 1, 2}};
  o.overlays.push_back(skel);
  const sdfkit::test::ScratchDir scratch;  // unique per run: two trees may run the suite at once
  const fs::path out = scratch.dir() / "sdfkit_overlay_reread.glb";
  io::write_field(out.string(), asset_of(m), f, o);
  const io::Asset back = io::load_asset(out.string());
  fs::remove(out);
  EXPECT_EQ(back.input_positions.size(), m.positions.size());
  EXPECT_EQ(back.input_triangles.size(), m.triangles.size());
}

TEST(Overlay, IndexOutOfRangeIsAnErrorAndWritesNothing) {
  const Mesh m = shapes::box(1, 1, 1, 1);
  const SdfField f = constant_field(m);
  io::WriteOptions o;
  io::Overlay bad;
  bad.name = "bad";
  bad.points = {{0, 0, 0}};
  bad.lines = {{0, 5}};
  o.overlays.push_back(bad);
  const sdfkit::test::ScratchDir scratch;  // unique per run: two trees may run the suite at once
  const fs::path out = scratch.dir() / "sdfkit_overlay_bad.glb";
  fs::remove(out);
  EXPECT_THROW(io::write_field(out.string(), asset_of(m), f, o), Error);
  EXPECT_FALSE(fs::exists(out));
}

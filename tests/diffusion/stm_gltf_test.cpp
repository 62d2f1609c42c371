// The mapping written as glTF TEXCOORD_1: vertices split where the faces around them use
// different charts, every face's corners carrying exactly the UVs gltf_corner_uv gave it (read
// back from the .glb's binary chunk), the positions welding back to the input mesh, and the
// .glb and .gltf clean under the Khronos glTF validator. Outputs that cannot hold it are usage errors.
#include "sdfkit/core/error.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/diffusion/stm.hpp"
#include "sdfkit/io/asset.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "mesh_text.hpp"
#include "scratch.hpp"

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

using namespace sdfkit;
namespace dif = sdfkit::diffusion;
namespace fs = std::filesystem;

namespace {

// A capsule along z with a hand-made skeleton: one bone and two caps, so faces at the caps'
// borders have corners in two charts.
struct Fixture {
  test::ScratchDir dir;
  io::Asset asset;
  dif::Stm stm;
  SdfField field;
  Fixture() {
    asset = io::load_asset(dir.write("capsule.off", test::off_text(shapes::capsule(0.5f, 3.0f, 32, 24))));
    skeleton::Skeleton s;
    for (int i = 0; i <= 6; ++i) s.nodes.push_back({{0.0f, 0.0f, -1.5f + 0.5f * static_cast<float>(i)}, 0.5f, {}, false});
    for (std::uint32_t i = 0; i < 6; ++i) s.edges.push_back({i, i + 1});
    const Mesh& m = asset.mesh;
    for (std::uint32_t v = 0; v < m.positions.size(); ++v) {
      const int k = std::clamp(static_cast<int>(std::lround((m.positions[v].z + 1.5f) / 0.5f)), 0, 6);
      s.nodes[static_cast<std::size_t>(k)].vertices.push_back(v);
    }
    dif::StmOptions o;
    o.atlas_size = 256;
    stm = dif::build_stm(m, s, o);
    for (const glm::vec3& p : m.positions) field.values.push_back(p.z);
  }
};

}  // namespace

TEST(StmGltf, Texcoord1IsPerCornerWithVerticesSplitAtChartBorders) {
  Fixture fx;
  const auto corner = dif::gltf_corner_uv(fx.stm.mapping, fx.asset.mesh);
  ASSERT_EQ(corner.size(), fx.asset.mesh.triangles.size());
  io::WriteOptions wo;
  wo.texcoord1 = corner;
  const std::string path = fx.dir.path("capsule.glb");
  io::write_field(path, fx.asset, fx.field, wo);

  // Read the .glb: JSON chunk, binary chunk.
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 20u);
  std::uint32_t json_len = 0;
  std::memcpy(&json_len, bytes.data() + 12, 4);
  const nlohmann::json j = nlohmann::json::parse(bytes.substr(20, json_len));
  const std::size_t bin = 20 + json_len + 8;
  const nlohmann::json& prim = j["meshes"][0]["primitives"][0];
  ASSERT_TRUE(prim["attributes"].contains("TEXCOORD_1"));
  const auto floats = [&](int accessor) {
    const nlohmann::json& a = j["accessors"][accessor];
    const nlohmann::json& v = j["bufferViews"][a["bufferView"].get<int>()];
    const std::size_t off = bin + v.value("byteOffset", 0u) + a.value("byteOffset", 0u);
    return bytes.data() + off;
  };
  const std::size_t n = j["accessors"][prim["attributes"]["TEXCOORD_1"].get<int>()]["count"];
  const std::size_t V = fx.asset.input_positions.size();
  EXPECT_GT(n, V) << "vertices on chart borders are split";
  EXPECT_LT(n, 2 * V);
  const char* uv = floats(prim["attributes"]["TEXCOORD_1"].get<int>());
  const char* pos = floats(prim["attributes"]["POSITION"].get<int>());
  const char* idx = floats(prim["indices"].get<int>());
  for (std::size_t f = 0; f < corner.size(); ++f)
    for (std::size_t k = 0; k < 3; ++k) {
      std::uint32_t i = 0;
      std::memcpy(&i, idx + 4 * (3 * f + k), 4);
      ASSERT_LT(i, n);
      glm::vec2 q;
      glm::vec3 p;
      std::memcpy(&q, uv + 8 * i, 8);
      std::memcpy(&p, pos + 12 * i, 12);
      EXPECT_EQ(q, corner[f][k]) << "face " << f;
      EXPECT_EQ(p, fx.asset.input_positions[fx.asset.input_triangles[f][k]]);
    }
  // The split vertices weld back to the input.
  const io::Asset back = io::load_asset(path);
  EXPECT_EQ(back.mesh.positions.size(), fx.asset.mesh.positions.size());
  EXPECT_EQ(back.mesh.triangles.size(), fx.asset.mesh.triangles.size());

  // Corners of a face lie in one chart: their UV span is at most a few texels.
  for (const auto& t : corner)
    for (std::size_t k = 0; k < 3; ++k) EXPECT_LT(glm::length(t[k] - t[(k + 1) % 3]) * 256.0f, 40.0f);
}

// The Khronos validator (tools/gltf-validator) finds no error in it. Suite named GltfValidator:
// CI's sanitizer stage leaves the tests that run node to the normal build (scripts/test.sh).
TEST(GltfValidator, StmTexcoord1AssetIsClean) {
  Fixture fx;
  io::WriteOptions wo;
  wo.texcoord1 = dif::gltf_corner_uv(fx.stm.mapping, fx.asset.mesh);
  const std::string path = fx.dir.path("capsule.glb"), text = fx.dir.path("capsule.gltf");
  io::write_field(path, fx.asset, fx.field, wo);
  io::write_field(text, fx.asset, fx.field, wo);
  ASSERT_TRUE(fs::exists(fs::path(SDFKIT_SOURCE_DIR) / "tools/gltf-validator/node_modules/gltf-validator"))
      << "run scripts/install-deps.sh (installs the Khronos glTF validator from npm)";
  EXPECT_EQ(std::system(("node " + std::string(SDFKIT_SOURCE_DIR) + "/tools/gltf-validator/validate.js " + path + " " + text).c_str()), 0);
}

TEST(StmGltf, Texcoord1WhereItCannotBeWrittenIsAUsageError) {
  Fixture fx;
  io::WriteOptions wo;
  wo.texcoord1 = dif::gltf_corner_uv(fx.stm.mapping, fx.asset.mesh);
  EXPECT_THROW(io::write_field(fx.dir.path("x.ply"), fx.asset, fx.field, wo), UsageError);
  EXPECT_FALSE(fs::exists(fx.dir.path("x.ply")));
  // A glTF input is written back whole: its primitives are not split.
  io::write_field(fx.dir.path("plain.glb"), fx.asset, fx.field);
  const io::Asset gltf = io::load_asset(fx.dir.path("plain.glb"));
  EXPECT_THROW(io::write_field(fx.dir.path("y.glb"), gltf, fx.field, wo), UsageError);
  wo.texcoord1.pop_back();
  EXPECT_THROW(io::write_field(fx.dir.path("z.glb"), fx.asset, fx.field, wo), InputError);
}

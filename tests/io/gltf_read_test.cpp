// glTF reader: node transforms and hierarchy, seams welded, primitive modes, accessor layouts,
// buffer storage variants.

#include "sdfkit/io/asset.hpp"

#include "gltf_builder.hpp"
#include "io_test_util.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

namespace sdfkit {
namespace {

using test::GltfBuilder;
using test::ScratchDir;

const std::string kScene0 = "\"scene\":0,\"scenes\":[{\"nodes\":[0]}]";

// A unit cube split at every edge (as a UV seam does): 24 vertices, 12 triangles, outward CCW.
struct SeamCube {
  std::vector<float> xyz;
  std::vector<std::uint16_t> idx;
};
SeamCube seam_cube() {
  const float c[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                         {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  const int q[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                       {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};
  SeamCube s;
  for (int f = 0; f < 6; ++f) {
    const auto base = static_cast<std::uint16_t>(s.xyz.size() / 3);
    for (int k = 0; k < 4; ++k)
      for (int a = 0; a < 3; ++a) s.xyz.push_back(c[q[f][k]][a]);
    for (int k : {0, 1, 2, 0, 2, 3}) s.idx.push_back(static_cast<std::uint16_t>(base + k));
  }
  return s;
}

// Every triangle's normal points away from `center`.
void expect_outward(const io::Asset& a, std::size_t first_tri, std::size_t count,
                    const glm::vec3& center) {
  for (std::size_t t = first_tri; t < first_tri + count; ++t) {
    const Triangle& tri = a.input_triangles[t];
    const glm::vec3 p0 = a.input_positions[tri[0]], p1 = a.input_positions[tri[1]],
                    p2 = a.input_positions[tri[2]];
    const glm::vec3 n = glm::cross(p1 - p0, p2 - p0);
    EXPECT_GT(glm::dot(n, (p0 + p1 + p2) / 3.0f - center), 0.0f) << "triangle " << t;
  }
}

void expect_near(const glm::vec3& a, const glm::vec3& b) {
  EXPECT_NEAR(a.x, b.x, 1e-5f);
  EXPECT_NEAR(a.y, b.y, 1e-5f);
  EXPECT_NEAR(a.z, b.z, 1e-5f);
}

TEST(ReadGltf, NodeTransformsHierarchyInstancesAndSeams) {
  const SeamCube cube = seam_cube();
  GltfBuilder b;
  const int pos = b.positions(cube.xyz);
  const int idx = b.indices(cube.idx);
  b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(pos) +
         "},\"indices\":" + std::to_string(idx) + "}");
  b.node("{\"mesh\":0,\"translation\":[10,0,0]}");
  b.node("{\"children\":[2],\"rotation\":[0,0,0.70710678,0.70710678]}");   // 90 deg about z
  b.node("{\"mesh\":0,\"matrix\":[2,0,0,0, 0,2,0,0, 0,0,2,0, 0,0,5,1]}");  // scale 2, z += 5
  ScratchDir dir;
  const io::Asset a = io::load_asset(
      dir.write("cubes.gltf", b.data_uri_gltf("\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}]")));
  EXPECT_EQ(a.format, io::Format::Gltf);
  ASSERT_EQ(a.input_positions.size(), 48u);
  ASSERT_EQ(a.input_triangles.size(), 24u);
  EXPECT_EQ(a.mesh.positions.size(), 16u);  // 8 corners per instance once the seams weld
  for (std::size_t v = 0; v < 24; ++v) {
    const glm::vec3 p(cube.xyz[3 * v], cube.xyz[3 * v + 1], cube.xyz[3 * v + 2]);
    expect_near(a.input_positions[v], p + glm::vec3(10, 0, 0));
    const glm::vec3 q = 2.0f * p + glm::vec3(0, 0, 5);
    expect_near(a.input_positions[24 + v], glm::vec3(-q.y, q.x, q.z));
  }
  expect_outward(a, 0, 12, glm::vec3(10.5f, 0.5f, 0.5f));
  expect_outward(a, 12, 12, glm::vec3(-1.0f, 1.0f, 6.0f));
  for (std::size_t v = 0; v < 48; ++v) {
    EXPECT_EQ(a.mesh.positions[a.input_to_welded[v]], a.input_positions[v]);
    EXPECT_EQ(a.input_to_welded[v] < 8, v < 24);  // instances never weld together
  }
  EXPECT_TRUE(a.warnings.empty());
}

TEST(ReadGltf, MirroringNodeKeepsTrianglesOutward) {
  GltfBuilder b;
  const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(pos) + "}}");
  b.node("{\"mesh\":0,\"scale\":[-1,1,1]}");
  ScratchDir dir;
  const io::Asset a = io::load_asset(dir.write("mirror.gltf", b.data_uri_gltf(kScene0)));
  ASSERT_EQ(a.input_triangles.size(), 1u);
  // Mirrored in x, the stored winding (0,1,2) faces -z; glTF flips it back to face +z.
  EXPECT_EQ(a.input_triangles[0], (Triangle{0, 2, 1}));
}

TEST(ReadGltf, StripsFansNonIndexedAndSkippedPrimitives) {
  GltfBuilder b;
  const int strip = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0});
  const int fan = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0});
  const int fan_idx = b.indices(std::vector<std::uint8_t>{0, 1, 2, 3, 4, 1});
  const int tris = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 5, 6, 5, 5, 5, 6, 5});
  const int line = b.positions({0, 0, 0, 1, 1, 1});
  b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(strip) + "},\"mode\":5}," +
         "{\"attributes\":{\"POSITION\":" + std::to_string(line) + "},\"mode\":1}," +
         "{\"attributes\":{\"POSITION\":" + std::to_string(fan) +
         "},\"indices\":" + std::to_string(fan_idx) + ",\"mode\":6}," +
         "{\"attributes\":{\"POSITION\":" + std::to_string(line) + "},\"mode\":0}," +
         "{\"attributes\":{\"POSITION\":" + std::to_string(tris) + "}}");
  b.node("{\"mesh\":0}");
  ScratchDir dir;
  const io::Asset a = io::load_asset(dir.write("modes.gltf", b.data_uri_gltf(kScene0)));
  const std::vector<Triangle> expected = {
      {0, 1, 2},   {2, 1, 3},                          // strip: p1 = {v1, v3, v2}, same winding
      {5, 6, 4},   {6, 7, 4},   {7, 8, 4}, {8, 5, 4},  // fan: {v(i+1), v(i+2), v0}, first vertex 4
      {9, 10, 11}, {12, 13, 14}};                      // plain triangles
  EXPECT_EQ(a.input_triangles, expected);
  EXPECT_EQ(a.input_positions.size(), 4u + 5u + 6u);
  for (const Triangle& t : a.input_triangles) {
    const glm::vec3 n = glm::cross(a.input_positions[t[1]] - a.input_positions[t[0]],
                                   a.input_positions[t[2]] - a.input_positions[t[0]]);
    EXPECT_GT(n.z, 0.0f);  // every primitive lies in a z plane facing +z
  }
  ASSERT_EQ(a.warnings.size(), 2u);
  EXPECT_EQ(a.warnings[0], "skipped 1 LINES primitives");
  EXPECT_EQ(a.warnings[1], "skipped 1 POINTS primitives");
}

TEST(ReadGltf, InterleavedStrideSparseAndQuantizedPositions) {
  GltfBuilder b;
  // Interleaved position + normal, stride 24, u32 indices.
  std::string inter;
  const float tri[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (const auto& p : tri) {
    for (float f : p) test::put(inter, f);
    for (float f : {0.f, 0.f, 1.f}) test::put(inter, f);
  }
  const int iv = b.view(inter, 24, 34962);
  const int ipos = b.accessor(iv, 0, 5126, 3, "VEC3", ",\"min\":[0,0,0],\"max\":[1,1,0]");
  const int inrm = b.accessor(iv, 12, 5126, 3, "VEC3");
  const int iidx = b.indices(std::vector<std::uint32_t>{0, 1, 2});
  // Sparse: base positions with vertex 2 replaced by (0, 3, 0).
  b.positions({0, 0, 0, 1, 0, 0, 9, 9, 9});
  const int sbase_view = b.last_view();
  std::string sidx, sval;
  test::put<std::uint16_t>(sidx, 2);
  while (sidx.size() % 4) sidx += '\0';
  for (float f : {0.f, 3.f, 0.f}) test::put(sval, f);
  const int siv = b.view(sidx), svv = b.view(sval);
  const int spos = b.accessor(
      sbase_view, 0, 5126, 3, "VEC3",
      ",\"sparse\":{\"count\":1,\"indices\":{\"bufferView\":" + std::to_string(siv) +
          ",\"componentType\":5123},\"values\":{\"bufferView\":" + std::to_string(svv) + "}}");
  // KHR_mesh_quantization: normalized SHORT positions.
  std::string qbytes;
  for (std::int16_t s : {0, 0, 0, 0, 32767, 0, 0, 0, 0, 0, -32767, 0}) test::put(qbytes, s);
  const int qpos = b.accessor(b.view(qbytes, 8, 34962), 0, 5122, 3, "VEC3",
                              ",\"normalized\":true,\"min\":[0,0,-1],\"max\":[1,0,0]");
  b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(ipos) +
         ",\"NORMAL\":" + std::to_string(inrm) + "},\"indices\":" + std::to_string(iidx) + "}," +
         "{\"attributes\":{\"POSITION\":" + std::to_string(spos) + "}}," +
         "{\"attributes\":{\"POSITION\":" + std::to_string(qpos) + "}}");
  b.node("{\"mesh\":0}");
  b.extra(
      "\"extensionsUsed\":[\"KHR_mesh_quantization\"],\"extensionsRequired\":[\"KHR_mesh_"
      "quantization\"]");
  ScratchDir dir;
  const io::Asset a = io::load_asset(dir.write("layouts.gltf", b.data_uri_gltf(kScene0)));
  ASSERT_EQ(a.input_positions.size(), 9u);
  EXPECT_EQ(a.input_positions[1], glm::vec3(1, 0, 0));
  EXPECT_EQ(a.input_positions[2], glm::vec3(0, 1, 0));
  EXPECT_EQ(a.input_positions[4], glm::vec3(1, 0, 0));
  EXPECT_EQ(a.input_positions[5], glm::vec3(0, 3, 0));
  EXPECT_EQ(a.input_positions[7], glm::vec3(1, 0, 0));
  EXPECT_EQ(a.input_positions[8], glm::vec3(0, 0, -1));
  EXPECT_EQ(a.input_triangles.size(), 3u);
}

TEST(ReadGltf, NoDefaultSceneUsesAllRootNodes) {
  GltfBuilder b;
  const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(pos) + "}}");
  b.node("{\"children\":[1],\"translation\":[0,0,1]}");
  b.node("{\"mesh\":0}");
  b.node("{\"mesh\":0,\"translation\":[0,0,2]}");
  ScratchDir dir;
  const io::Asset a = io::load_asset(dir.write("noscene.gltf", b.data_uri_gltf("")));
  ASSERT_EQ(a.input_positions.size(), 6u);
  EXPECT_EQ(a.input_positions[0].z, 1.0f);
  EXPECT_EQ(a.input_positions[3].z, 2.0f);
}

TEST(ReadGltf, DataUriExternalBufferAndGlbLoadTheSame) {
  const SeamCube cube = seam_cube();
  GltfBuilder b;
  const int pos = b.positions(cube.xyz);
  const int idx = b.indices(cube.idx);
  b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(pos) +
         "},\"indices\":" + std::to_string(idx) + "}");
  b.node("{\"mesh\":0,\"translation\":[1,2,3]}");
  ScratchDir dir;
  dir.write("cube.bin", b.bin());
  const io::Asset external =
      io::load_asset(dir.write("external.gltf", b.json("cube.bin", kScene0)));
  const io::Asset data_uri = io::load_asset(dir.write("datauri.gltf", b.data_uri_gltf(kScene0)));
  const io::Asset glb = io::load_asset(dir.write("binary.GLB", b.glb(kScene0)));
  EXPECT_EQ(glb.format, io::Format::Glb);
  ASSERT_EQ(external.input_positions.size(), 24u);
  EXPECT_EQ(external.input_positions[0], glm::vec3(1, 2, 3));
  for (const io::Asset* other : {&data_uri, &glb}) {
    EXPECT_EQ(other->input_positions, external.input_positions);
    EXPECT_EQ(other->input_triangles, external.input_triangles);
    EXPECT_EQ(other->input_to_welded, external.input_to_welded);
  }
}

}  // namespace
}  // namespace sdfkit

// Readers for OFF, OBJ and PLY: every variant the formats allow, and the real CGAL meshes.

#include "sdfkit/io/asset.hpp"

#include "analytic.hpp"
#include "io_test_util.hpp"

#include <gtest/gtest.h>

#include <sstream>

namespace sdfkit {
namespace {

using io::Format;
using test::ScratchDir;

// A unit cube as 8 vertices and 6 quads (outward CCW), the reference for every format.
const std::vector<glm::vec3> kCubeV = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                       {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
const std::vector<std::array<std::uint32_t, 4>> kCubeQ = {
    {0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};

// The fan triangulation every reader must produce for kCubeQ.
std::vector<Triangle> cube_triangles() {
  std::vector<Triangle> t;
  for (const auto& q : kCubeQ) {
    t.push_back({q[0], q[1], q[2]});
    t.push_back({q[0], q[2], q[3]});
  }
  return t;
}

void expect_cube(const io::Asset& a) {
  EXPECT_EQ(a.input_positions, kCubeV);
  EXPECT_EQ(a.input_triangles, cube_triangles());
  EXPECT_EQ(a.mesh.positions.size(), 8u);
  EXPECT_EQ(a.mesh.triangles, cube_triangles());
  ASSERT_EQ(a.input_to_welded.size(), 8u);
  for (std::uint32_t i = 0; i < 8; ++i) EXPECT_EQ(a.input_to_welded[i], i);
}

TEST(FormatFromPath, KnownExtensionsAnyCase) {
  EXPECT_EQ(io::format_from_path("a/b.gltf"), Format::Gltf);
  EXPECT_EQ(io::format_from_path("x.GLB"), Format::Glb);
  EXPECT_EQ(io::format_from_path("x.Obj"), Format::Obj);
  EXPECT_EQ(io::format_from_path("dir.d/x.off"), Format::Off);
  EXPECT_EQ(io::format_from_path("x.PLY"), Format::Ply);
  EXPECT_EQ(io::format_from_path("x.txt"), Format::Txt);
}

TEST(FormatFromPath, UnknownExtensionIsOneLineError) {
  test::expect_input_error([] { io::format_from_path("mesh.xyz"); }, "mesh.xyz",
                           "unknown extension '.xyz' (expected .gltf, .glb, .obj, .off, .ply)");
  test::expect_input_error([] { io::format_from_path("mesh"); }, "mesh", "no file extension");
  test::expect_input_error([] { io::load_asset("values.txt"); }, "values.txt", "not meshes");
}

TEST(ReadOff, QuadsWithCommentsAndExtraColumns) {
  ScratchDir dir;
  std::ostringstream s;
  s << "# a comment before the keyword\nCOFF\n# counts follow\n8 6 12\n";
  for (const auto& v : kCubeV) s << v.x << ' ' << v.y << ' ' << v.z << " 255 0 0 255  # colour\n";
  s << "\n";
  for (const auto& q : kCubeQ) s << "4  " << q[0] << ' ' << q[1] << ' ' << q[2] << ' ' << q[3] << " 0.5 0.5 0.5\n";
  const io::Asset a = io::load_asset(dir.write("cube.off", s.str()));
  EXPECT_EQ(a.format, Format::Off);
  expect_cube(a);
  EXPECT_TRUE(a.warnings.empty());
}

TEST(ReadOff, CountsOnKeywordLineAndNoFinalNewline) {
  ScratchDir dir;
  const std::string p = dir.write("tri.off", "OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2");
  const io::Asset a = io::load_asset(p);
  EXPECT_EQ(a.input_positions.size(), 3u);
  ASSERT_EQ(a.input_triangles.size(), 1u);
  EXPECT_EQ(a.input_triangles[0], (Triangle{0, 1, 2}));
}

TEST(ReadOff, NormalsVariantAndCrLf) {
  ScratchDir dir;
  const std::string p = dir.write(
      "tri.off", "NOFF\r\n3 1 0\r\n0 0 0 0 0 1\r\n1 0 0 0 0 1\r\n0 1 0 0 0 1\r\n3 0 1 2\r\n");
  const io::Asset a = io::load_asset(p);
  EXPECT_EQ(a.input_positions[1], glm::vec3(1, 0, 0));
  EXPECT_EQ(a.input_triangles.size(), 1u);
}

TEST(ReadOff, WeldingMergesDuplicatesAndKeepsInputOrder) {
  ScratchDir dir;
  // Two triangles sharing an edge, stored with duplicated vertices (as a seam would).
  const std::string p = dir.write("seam.off",
                                  "OFF\n6 2 0\n0 0 0\n1 0 0\n0 1 0\n1 0 0\n1 1 0\n0 1 0\n"
                                  "3 0 1 2\n3 3 4 5\n");
  const io::Asset a = io::load_asset(p);
  EXPECT_EQ(a.input_positions.size(), 6u);
  EXPECT_EQ(a.mesh.positions.size(), 4u);
  EXPECT_EQ(a.input_to_welded[3], a.input_to_welded[1]);
  EXPECT_EQ(a.input_to_welded[5], a.input_to_welded[2]);
  for (std::size_t i = 0; i < 6; ++i)
    EXPECT_EQ(a.mesh.positions[a.input_to_welded[i]], a.input_positions[i]);
  ASSERT_EQ(a.mesh.triangles.size(), 2u);
  for (std::size_t f = 0; f < 2; ++f)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(a.mesh.triangles[f][k], a.input_to_welded[a.input_triangles[f][k]]);
}

TEST(ReadOff, WeldToleranceJoinsNearbyVertices) {
  ScratchDir dir;
  const std::string p = dir.write("near.off",
                                  "OFF\n6 2 0\n0 0 0\n1 0 0\n0 1 0\n1.00001 0 0\n1 1 0\n0 1 0\n"
                                  "3 0 1 2\n3 3 4 5\n");
  EXPECT_EQ(io::load_asset(p).mesh.positions.size(), 5u);
  EXPECT_EQ(io::load_asset(p, {.weld_tolerance = 1e-3f}).mesh.positions.size(), 4u);
}

TEST(ReadObj, AllFaceFormsAndNegativeIndices) {
  ScratchDir dir;
  std::ostringstream s;
  s << "# cube\nmtllib cube.mtl\no cube\n";
  for (const auto& v : kCubeV) s << "v " << v.x << ' ' << v.y << ' ' << v.z << "\n";
  s << "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\ng side\nusemtl red\ns off\n";
  const auto& q = kCubeQ;
  auto idx = [](std::uint32_t i) { return i + 1; };
  s << "f " << idx(q[0][0]) << ' ' << idx(q[0][1]) << ' ' << idx(q[0][2]) << ' ' << idx(q[0][3]) << "\n";
  s << "f " << idx(q[1][0]) << "/1 " << idx(q[1][1]) << "/2 " << idx(q[1][2]) << "/3 " << idx(q[1][3]) << "/1\n";
  s << "f " << idx(q[2][0]) << "//1 " << idx(q[2][1]) << "//1 " << idx(q[2][2]) << "//1 " << idx(q[2][3]) << "//1\n";
  s << "f\t" << idx(q[3][0]) << "/1/1 " << idx(q[3][1]) << "/2/1 " << idx(q[3][2]) << "/3/1 " << idx(q[3][3]) << "/1/1  # c\n";
  // Negative: -1 is the last vertex read so far (index 7).
  auto neg = [](std::uint32_t i) { return static_cast<int>(i) - 8; };
  s << "f " << neg(q[4][0]) << ' ' << neg(q[4][1]) << "/-1 " << neg(q[4][2]) << "//-1 " << neg(q[4][3]) << "/-2/-1\r\n";
  s << "f " << idx(q[5][0]) << ' ' << idx(q[5][1]) << ' ' << idx(q[5][2]) << ' ' << idx(q[5][3]);
  const io::Asset a = io::load_asset(dir.write("cube.obj", s.str()));
  EXPECT_EQ(a.format, Format::Obj);
  expect_cube(a);
}

TEST(ReadObj, LinesAndPointsAreSkippedWithAWarning) {
  ScratchDir dir;
  const io::Asset a = io::load_asset(
      dir.write("mixed.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\np 3\nf 1 2 3\n"));
  EXPECT_EQ(a.input_triangles.size(), 1u);
  ASSERT_EQ(a.warnings.size(), 2u);
  EXPECT_NE(a.warnings[0].find("line"), std::string::npos);
}

// Writes the cube as PLY with extra properties and elements around the ones that matter.
std::string cube_ply(const std::string& format) {
  const bool ascii = format == "ascii";
  const bool big = format == "binary_big_endian";
  std::string s = "ply\nformat " + format + " 1.0\ncomment made by sdfkit tests\n";
  s += "obj_info nothing\nelement material 1\nproperty uchar r\nproperty list uchar float tags\n";
  s += "element vertex 8\nproperty double x\nproperty float nx\nproperty float y\n";
  s += "property list ushort int junk\nproperty uchar red\nproperty int16 z\n";
  s += "element face 6\nproperty uchar flags\nproperty list ushort uint vertex_indices\n";
  s += "property list uchar int8 extra\nelement edge 1\nproperty int a\nproperty int b\n";
  s += "end_header\n";
  std::ostringstream t;
  if (ascii) {
    t << "7 2 0.5 1.5\n";
    for (const auto& v : kCubeV) t << v.x << " 0.25 " << v.y << " 2 -1 7 200 " << v.z << "\n";
    for (const auto& q : kCubeQ) t << "9 4 " << q[0] << ' ' << q[1] << ' ' << q[2] << ' ' << q[3] << " 1 -3\n";
    t << "0 1\n";
    return s + t.str();
  }
  using test::put;
  put<std::uint8_t>(s, 7, big);
  put<std::uint8_t>(s, 2, big);
  put<float>(s, 0.5f, big);
  put<float>(s, 1.5f, big);
  for (const auto& v : kCubeV) {
    put<double>(s, v.x, big);
    put<float>(s, 0.25f, big);
    put<float>(s, v.y, big);
    put<std::uint16_t>(s, 2, big);
    put<std::int32_t>(s, -1, big);
    put<std::int32_t>(s, 7, big);
    put<std::uint8_t>(s, 200, big);
    put<std::int16_t>(s, static_cast<std::int16_t>(v.z), big);
  }
  for (const auto& q : kCubeQ) {
    put<std::uint8_t>(s, 9, big);
    put<std::uint16_t>(s, 4, big);
    for (std::uint32_t i : q) put<std::uint32_t>(s, i, big);
    put<std::uint8_t>(s, 1, big);
    put<std::int8_t>(s, -3, big);
  }
  put<std::int32_t>(s, 0, big);
  put<std::int32_t>(s, 1, big);
  return s;
}

class ReadPly : public ::testing::TestWithParam<std::string> {};

TEST_P(ReadPly, AnyTypesExtraPropertiesAndElements) {
  ScratchDir dir;
  const io::Asset a = io::load_asset(dir.write("cube.ply", cube_ply(GetParam())));
  EXPECT_EQ(a.format, Format::Ply);
  expect_cube(a);
}

INSTANTIATE_TEST_SUITE_P(Encodings, ReadPly,
                         ::testing::Values("ascii", "binary_little_endian", "binary_big_endian"));

TEST(ReadPlyVariants, VertexIndexNameAndCrLfHeader) {
  ScratchDir dir;
  const std::string p = dir.write(
      "tri.ply",
      "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty float x\r\nproperty float y\r\n"
      "property float z\r\nelement face 1\r\nproperty list uchar int vertex_index\r\n"
      "end_header\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n");
  const io::Asset a = io::load_asset(p);
  EXPECT_EQ(a.input_positions.size(), 3u);
  EXPECT_EQ(a.input_triangles.size(), 1u);
}

struct RealMesh {
  const char* name;
  std::size_t vertices;
  std::size_t faces;
};

class ReadRealMesh : public ::testing::TestWithParam<RealMesh> {};

TEST_P(ReadRealMesh, CountsMatchTheHeader) {
  const RealMesh m = GetParam();
  const io::Asset a = io::load_asset(test::data_mesh(m.name));
  EXPECT_EQ(a.input_positions.size(), m.vertices);
  EXPECT_EQ(a.input_triangles.size(), m.faces);
  EXPECT_EQ(a.mesh.triangles.size(), m.faces);
  EXPECT_LE(a.mesh.positions.size(), m.vertices);
  EXPECT_GT(bounding_box(a.mesh.positions).diagonal(), 0.0f);
}

INSTANTIATE_TEST_SUITE_P(Cgal, ReadRealMesh,
                         ::testing::Values(RealMesh{"cow.off", 2904, 5804},
                                           RealMesh{"elephant.off", 2775, 5558},
                                           RealMesh{"armadillo.off", 26002, 52000},
                                           RealMesh{"bunny00.off", 37706, 75408},
                                           RealMesh{"cube-ouvert.off", 9, 10},
                                           RealMesh{"degtri_sliding.off", 8, 8}),
                         [](const ::testing::TestParamInfo<RealMesh>& p) {
                           std::string n = p.param.name;
                           for (char& ch : n)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return n;
                         });

}  // namespace
}  // namespace sdfkit

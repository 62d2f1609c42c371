// Reading results back: read_field and read_values_txt round-trip with write_field for every
// output format; welded_values maps input-order values onto the welded mesh.

#include "sdfkit/core/error.hpp"
#include "sdfkit/io/field.hpp"

#include "gltf_builder.hpp"
#include "io_test_util.hpp"

#include <gtest/gtest.h>

namespace sdfkit {
namespace {

using test::GltfBuilder;
using test::ScratchDir;
using test::kCubeOff;
using test::ramp_field;

TEST(FieldRead, RoundTripsPerVertexThroughGlbGltfPly) {
  ScratchDir dir;
  const io::Asset a = io::load_asset(dir.write("cube.off", kCubeOff));
  const SdfField f = ramp_field(a, SdfDomain::Vertex);
  for (const char* name : {"r.glb", "r.gltf", "r.ply"}) {
    SCOPED_TRACE(name);
    io::write_field(dir.path(name), a, f);
    const io::FieldFile r = io::read_field(dir.path(name));
    EXPECT_EQ(r.domain, SdfDomain::Vertex);
    ASSERT_EQ(r.values.size(), a.input_positions.size());
    EXPECT_EQ(r.asset.mesh.triangles, a.mesh.triangles);
    const std::vector<float> w = io::welded_values(r.asset, r.domain, r.values);
    EXPECT_EQ(w, f.values);  // bit-exact: stored as float32
  }
}

TEST(FieldRead, RoundTripsPerFaceThroughPlyAndTxt) {
  ScratchDir dir;
  const io::Asset a = io::load_asset(dir.write("cube.off", kCubeOff));
  const SdfField f = ramp_field(a, SdfDomain::Face);
  io::write_field(dir.path("r.ply"), a, f);
  const io::FieldFile r = io::read_field(dir.path("r.ply"));
  EXPECT_EQ(r.domain, SdfDomain::Face);
  EXPECT_EQ(r.values, f.values);

  io::write_field(dir.path("r.txt"), a, f);
  const std::vector<float> t = io::read_values_txt(dir.path("r.txt"));
  EXPECT_EQ(t, f.values);  // %.9g round-trips float32
  EXPECT_EQ(io::domain_of_count(a, t.size(), "r.txt"), SdfDomain::Face);
}

TEST(FieldRead, TxtPerVertexInInputOrder) {
  ScratchDir dir;
  const io::Asset a = io::load_asset(dir.write("cube.off", kCubeOff));
  const SdfField f = ramp_field(a, SdfDomain::Vertex);
  io::write_field(dir.path("r.txt"), a, f);
  const std::vector<float> t = io::read_values_txt(dir.path("r.txt"));
  EXPECT_EQ(io::domain_of_count(a, t.size(), "r.txt"), SdfDomain::Vertex);
  EXPECT_EQ(io::welded_values(a, SdfDomain::Vertex, t), f.values);
}

// A glTF quad with a seam: 6 input vertices welded into 4; two instances of the mesh.
TEST(FieldRead, GltfWriteBackWithSeamsAndInstances) {
  GltfBuilder b;
  const int pos = b.positions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0});
  b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(pos) + "}}");
  b.node("{\"name\":\"root\",\"mesh\":0,\"children\":[1]}");
  b.node("{\"name\":\"child\",\"mesh\":0,\"translation\":[0,0,3]}");
  ScratchDir dir;
  const std::string in = dir.write("quad.glb", b.glb("\"scene\":0,\"scenes\":[{\"nodes\":[0]}]"));
  const io::Asset a = io::load_asset(in);
  ASSERT_EQ(a.input_positions.size(), 12u);
  ASSERT_EQ(a.mesh.vertex_count(), 8u);
  const SdfField f = ramp_field(a, SdfDomain::Vertex);
  io::write_field(dir.path("out.glb"), a, f);
  const io::FieldFile r = io::read_field(dir.path("out.glb"));
  ASSERT_EQ(r.values.size(), 12u);
  // Each instance reads back its own values (the second draws a copy of the mesh carrying them).
  const std::vector<float> w = io::welded_values(r.asset, r.domain, r.values);
  for (std::size_t v = 0; v < 12; ++v) EXPECT_EQ(r.values[v], f.values[a.input_to_welded[v]]) << v;
  EXPECT_EQ(w.size(), 8u);
}

TEST(FieldRead, PlainMeshesHaveNoValues) {
  ScratchDir dir;
  const std::string off = dir.write("cube.off", kCubeOff);
  try {
    io::read_field(off);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("holds no values"), std::string::npos) << e.what();
  }
  const io::FieldFile r = io::read_field(off, io::ValuesRequired::No);
  EXPECT_TRUE(r.values.empty());
  EXPECT_EQ(r.asset.mesh.face_count(), 12u);

  // A glb without _SDF: an error naming the attribute, or no values when optional.
  const io::Asset a = io::load_asset(off);
  GltfBuilder b;
  const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(pos) + "}}");
  b.node("{\"mesh\":0}");
  const std::string glb = dir.write("tri.glb", b.glb("\"scene\":0,\"scenes\":[{\"nodes\":[0]}]"));
  try {
    io::read_field(glb);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no _SDF attribute"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(io::read_field(glb, io::ValuesRequired::No).values.empty());
  EXPECT_THROW(io::read_field(dir.path("values.txt")), InputError);
}

TEST(FieldRead, TxtErrorsNameTheLine) {
  ScratchDir dir;
  EXPECT_EQ(io::read_values_txt(dir.write("ok.txt", "1\n  2.5e-1 \r\n\n-3\n")),
            (std::vector<float>{1.0f, 0.25f, -3.0f}));
  try {
    io::read_values_txt(dir.write("bad.txt", "1\n2\n3 4\n"));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("line 3: '3 4' is not a number"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos);
  }
  EXPECT_THROW(io::read_values_txt(dir.path("missing.txt")), InputError);
}

TEST(FieldRead, CountsThatFitNothingAreErrors) {
  ScratchDir dir;
  const io::Asset a = io::load_asset(dir.write("cube.off", kCubeOff));
  EXPECT_THROW(io::domain_of_count(a, 5, "v.txt"), InputError);
  const std::vector<float> five(5, 1.0f);
  EXPECT_THROW(io::welded_values(a, SdfDomain::Vertex, five), InputError);
  EXPECT_THROW(io::welded_values(a, SdfDomain::Face, five), InputError);
}

}  // namespace
}  // namespace sdfkit

// Bad input: each case is one InputError line naming the file and the problem, never a crash,
// a hang or a huge allocation.

#include "sdfkit/io/asset.hpp"

#include "gltf_builder.hpp"
#include "io_test_util.hpp"

#include "sdfkit/core/log.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>

namespace sdfkit {
namespace {

using test::ScratchDir;

void expect_bad(const ScratchDir& dir, const std::string& name, const std::string& content,
                const std::string& needle) {
  const std::string p = dir.write(name, content);
  test::expect_input_error([&] { io::load_asset(p); }, p, needle);
}

TEST(BadInput, MissingFileAndDirectory) {
  ScratchDir dir;
  const std::string missing = dir.path("missing.off");
  test::expect_input_error([&] { io::load_asset(missing); }, missing, "no such file");
  const std::string d = dir.path("folder.ply");
  std::filesystem::create_directory(d);
  test::expect_input_error([&] { io::load_asset(d); }, d, "is a directory");
  const std::string g = dir.path("missing.glb");
  test::expect_input_error([&] { io::load_asset(g); }, g, "no such file");
}

TEST(BadInput, Off) {
  ScratchDir dir;
  expect_bad(dir, "empty.off", "", "the file is empty");
  expect_bad(dir, "keyword.off", "PFF\n3 1 0\n", "not an OFF file");
  expect_bad(dir, "fourd.off", "4OFF\n1 0 0\n0 0 0 0\n", "unsupported OFF variant");
  expect_bad(dir, "huge.off", "OFF\n1000000000000 1 0\n0 0 0\n", "truncated file");
  expect_bad(dir, "truncated.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1",
             "unexpected end of file");
  expect_bad(dir, "shortvertex.off", "OFF\n3 1 0\n0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
             "line 3: expected coordinate 3 of vertex 0, found the end of the line");
  expect_bad(dir, "number.off", "OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n",
             "line 4: expected coordinate 2 of vertex 1, found 'x'");
  expect_bad(dir, "badcount.off", "OFF\nthree 1 0\n", "expected the vertex count");
  expect_bad(dir, "range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
             "face 0 uses vertex 3 but the file has 3 vertices");
  expect_bad(dir, "negative.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", "uses vertex -1");
  expect_bad(dir, "nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n", "non-finite");
  expect_bad(dir, "inf.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 -inf 0\n3 0 1 2\n", "non-finite");
  expect_bad(dir, "nofaces.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", "no triangles");
  expect_bad(dir, "edgesonly.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", "no triangles");
  expect_bad(dir, "hugeface.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2000000000 0 1 2\n",
             "impossible corner count");
  expect_bad(dir, "binary.off",
             std::string("OFF\n3 1 0\n\x01\x02\xff\x00", 14) + std::string(40, '\x01'),
             "expected coordinate 1 of vertex 0, found '????");
}

TEST(BadInput, Obj) {
  ScratchDir dir;
  expect_bad(dir, "empty.obj", "", "no triangles");
  expect_bad(dir, "comments.obj", "# nothing\nv 0 0 0\n", "no triangles");
  expect_bad(dir, "range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
             "triangle 0 uses vertex 4 but the file has 3 vertices");
  expect_bad(dir, "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "line 4: vertex index 0");
  expect_bad(dir, "negative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
             "before the first vertex");
  expect_bad(dir, "number.obj", "v 0 0 0\nv 1 zero 0\n",
             "line 2: expected coordinate 2 of vertex 2, found 'zero'");
  expect_bad(dir, "short.obj", "v 0 0",
             "unexpected end of file: expected coordinate 3 of vertex 1");
  expect_bad(dir, "corner.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", "expected a face corner");
  expect_bad(dir, "nan.obj", "v 0 0 0\nv 1 0 NaN\nv 0 1 0\nf 1 2 3\n", "non-finite");
  expect_bad(dir, "overflow.obj", "v 0 0 0\nv 1 0 1e999\nv 0 1 0\nf 1 2 3\n",
             "expected coordinate 3");
  expect_bad(dir, "lines.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n", "no triangles");
}

TEST(BadInput, Ply) {
  ScratchDir dir;
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string bin_head =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  expect_bad(dir, "empty.ply", "", "not a PLY file");
  expect_bad(dir, "magic.ply", "plx\n", "not a PLY file");
  expect_bad(dir, "noend.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", "no 'end_header'");
  expect_bad(dir, "noformat.ply", "ply\nelement vertex 0\nend_header\n", "no 'format'");
  expect_bad(dir, "format.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n",
             "unknown PLY format");
  expect_bad(dir, "type.ply",
             "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n",
             "line 4: unknown property type 'float128'");
  expect_bad(dir, "keyword.ply", "ply\nformat ascii 1.0\nelemnt vertex 1\nend_header\n",
             "unknown PLY header line");
  expect_bad(dir, "noxyz.ply",
             "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n",
             "no x, y and z");
  expect_bad(dir, "huge.ply",
             "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n"
             "property float x\nproperty float y\nproperty float z\nend_header\n",
             "truncated file");
  expect_bad(dir, "hugeascii.ply",
             "ply\nformat ascii 1.0\nelement vertex 100000000\nproperty float x\n"
             "property float y\nproperty float z\nend_header\n0 0 0\n",
             "truncated file");
  expect_bad(dir, "truncated.ply", head + "0 0 0\n1 0 0\n0 1 0\n3 0 1\n", "unexpected end of file");
  expect_bad(dir, "number.ply", head + "0 0 0\n1 0 0\n0 1 q\n3 0 1 2\n", "found 'q'");
  expect_bad(dir, "range.ply", head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
             "face 0 uses vertex 7 but the file has 3 vertices");
  expect_bad(dir, "nan.ply", head + "0 0 0\n1 0 0\n0 1 nan\n3 0 1 2\n", "non-finite");
  std::string bin = bin_head;
  for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) test::put(bin, f);
  test::put<std::uint8_t>(bin, 3);
  test::put<std::int32_t>(bin, 0);  // two indices short
  expect_bad(dir, "bintruncated.ply", bin, "unexpected end of file");
  std::string hugelist = bin_head;
  for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) test::put(hugelist, f);
  test::put<std::uint8_t>(hugelist, 20);
  test::put<std::int32_t>(hugelist, 0);
  expect_bad(dir, "binlist.ply", hugelist, "unexpected end of file");
  std::string binrange = bin_head;
  for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) test::put(binrange, f);
  test::put<std::uint8_t>(binrange, 3);
  for (std::int32_t i : {0, 1, -5}) test::put(binrange, i);
  expect_bad(dir, "binrange.ply", binrange, "uses vertex -5");
  expect_bad(dir, "noface.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
             "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n",
             "no triangles");
}

// A valid one-triangle glTF with `mutate` applied to the builder's pieces.
test::GltfBuilder triangle_gltf(int mode = 4) {
  test::GltfBuilder b;
  const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  const int idx = b.indices(std::vector<std::uint16_t>{0, 1, 2});
  b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(pos) +
         "},\"indices\":" + std::to_string(idx) + ",\"mode\":" + std::to_string(mode) + "}");
  b.node("{\"mesh\":0}");
  return b;
}

const std::string kScene = "\"scene\":0,\"scenes\":[{\"nodes\":[0]}]";

TEST(BadInput, Gltf) {
  ScratchDir dir;
  expect_bad(dir, "empty.gltf", "", "invalid glTF");
  expect_bad(dir, "json.gltf", "{\"asset\":{\"version\":\"2.0\"},\"meshes\":[", "invalid glTF");
  expect_bad(dir, "notjson.gltf", "solid cube\nfacet normal 0 0 1\n", "invalid glTF");
  expect_bad(dir, "noversion.gltf", "{\"meshes\":[]}", "invalid glTF");
  expect_bad(dir, "nothing.gltf", "{\"asset\":{\"version\":\"2.0\"}}", "no triangle primitives");
  expect_bad(dir, "magic.glb", "glTX\x02\0\0\0", "invalid glTF");
  {
    const std::string glb = triangle_gltf().glb(kScene);
    expect_bad(dir, "truncated.glb", glb.substr(0, glb.size() - 10), "invalid glTF");
    // The BIN chunk claiming 8 bytes more than the GLB holds: tinygltf alone lets its data run
    // past the file (it forgets the chunk's 8-byte header).
    std::string longer = glb;
    const std::size_t bin_at = 20 + static_cast<unsigned char>(glb[12]) +
                               256u * static_cast<unsigned char>(glb[13]);
    std::uint32_t bin_size = 0;
    std::memcpy(&bin_size, glb.data() + bin_at, 4);
    bin_size += 8;
    std::memcpy(longer.data() + bin_at, &bin_size, 4);
    expect_bad(dir, "binpast.glb", longer, "GLB chunk 1 (" + std::to_string(bin_size) +
                                               " bytes) reaches past the GLB's length");
  }
  expect_bad(dir, "lines.gltf", triangle_gltf(1).data_uri_gltf(kScene),
             "no triangle primitives (skipped 1 LINES primitives)");
  expect_bad(dir, "points.glb", triangle_gltf(0).glb(kScene), "no triangle primitives");
  {
    test::GltfBuilder b = triangle_gltf();
    expect_bad(dir, "missingbin.gltf", b.json("nowhere.bin", kScene), "invalid glTF");
  }
  {
    test::GltfBuilder b;
    const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    const int idx = b.indices(std::vector<std::uint16_t>{0, 1, 3});
    b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(pos) +
           "},\"indices\":" + std::to_string(idx) + "}");
    b.node("{\"mesh\":0}");
    expect_bad(dir, "range.gltf", b.data_uri_gltf(kScene),
               "mesh 0 primitive 0 uses vertex 3 but its POSITION has 3 vertices");
  }
  {
    test::GltfBuilder b;
    const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    // An accessor that claims more vertices than its bufferView holds.
    const int big = b.accessor(0, 0, 5126, 300, "VEC3", ",\"min\":[0,0,0],\"max\":[1,1,0]");
    (void)pos;
    b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(big) + "}}");
    b.node("{\"mesh\":0}");
    expect_bad(dir, "overrun.gltf", b.data_uri_gltf(kScene),
               "POSITION accessor 1 reads past the end of bufferView 0");
  }
  {
    test::GltfBuilder b;
    const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    const int uv = b.accessor(0, 0, 5126, 3, "VEC2");
    b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(uv) +
           ",\"NORMAL\":" + std::to_string(pos) + "}}");
    b.node("{\"mesh\":0}");
    expect_bad(dir, "type.gltf", b.data_uri_gltf(kScene), "POSITION accessor 1 has the wrong type");
  }
  {
    test::GltfBuilder b;
    const float nan = std::nanf("");
    const int pos = b.positions({0, 0, 0, 1, nan, 0, 0, 1, 0});
    b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(pos) + "}}");
    b.node("{\"mesh\":0}");
    expect_bad(dir, "nan.glb", b.glb(kScene), "non-finite");
  }
  {
    test::GltfBuilder b = triangle_gltf();
    b.node("{\"children\":[2]}");
    b.node("{\"children\":[1]}");
    expect_bad(dir, "cycle.gltf", b.data_uri_gltf("\"scene\":0,\"scenes\":[{\"nodes\":[1]}]"),
               "cycle");
  }
  {
    test::GltfBuilder b = triangle_gltf();
    b.extra(
        "\"extensionsUsed\":[\"KHR_draco_mesh_compression\"],"
        "\"extensionsRequired\":[\"KHR_draco_mesh_compression\"]");
    expect_bad(dir, "draco.gltf", b.data_uri_gltf(kScene),
               "requires the glTF extension KHR_draco_mesh_compression");
  }
}

// Every prefix of a valid file loads or fails with an InputError: no crash, no hang, no other
// exception (bad_alloc, out_of_range...).
void truncation_sweep(const ScratchDir& dir, const std::string& name, const std::string& bytes) {
  std::size_t loaded = 0;
  for (std::size_t n = 0; n <= bytes.size(); ++n) {
    // A new file per prefix: rewriting one file over and over is slow on some file systems.
    const std::string p = dir.write(std::to_string(n) + "_" + name, bytes.substr(0, n));
    try {
      io::load_asset(p);
      ++loaded;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(p + ": ", 0), 0u) << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << name << " cut at " << n << ": " << e.what();
    }
  }
  EXPECT_GE(loaded, 1u) << name;  // at least the whole file
}

TEST(BadInput, EveryTruncationIsAnInputError) {
  ScratchDir dir;
  set_log_level(LogLevel::Error);  // tinygltf warnings about cut files are expected
  const std::string off = "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 2 1 3\n";
  truncation_sweep(dir, "cut.off", off);
  truncation_sweep(dir, "cut.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  std::string ply =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) test::put(ply, f, true);
  test::put<std::uint8_t>(ply, 3);
  for (std::int32_t i : {0, 1, 2}) test::put(ply, i, true);
  truncation_sweep(dir, "cut.ply", ply);
  truncation_sweep(dir, "cut.glb", triangle_gltf().glb(kScene));
  truncation_sweep(dir, "cut.gltf", triangle_gltf().data_uri_gltf(kScene));
  set_log_level(LogLevel::Warning);
}

}  // namespace
}  // namespace sdfkit

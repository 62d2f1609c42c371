// The loaders' large-file paths: an OBJ big enough to be parsed in several chunks on several
// threads, and a binary PLY big enough for the parallel vertex rows, read back exactly.
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/io/field.hpp"

#include "io_test_util.hpp"
#include "readers.hpp"

#include <gtest/gtest.h>

#include <charconv>
#include <cstdlib>
#include <filesystem>

namespace sdfkit {
namespace {

using test::ScratchDir;

// A level-7 icosphere: 164k vertices, 328k triangles (an 11 MB OBJ: several 4 MiB chunks).
const Mesh& big_mesh() {
  static const Mesh m = shapes::icosphere(1.0f, 7);
  return m;
}

TEST(LargeRead, ObjInChunksMatchesTheMeshExactly) {
  const Mesh& m = big_mesh();
  std::string obj = "# generated\n";
  char buf[64];
  const auto num = [&](auto v) { obj.append(buf, std::to_chars(buf, buf + sizeof buf, v).ptr); };
  for (const glm::vec3& p : m.positions) {
    obj += "v ";
    num(p.x), obj += ' ', num(p.y), obj += ' ', num(p.z), obj += '\n';
  }
  const auto nv = static_cast<std::int64_t>(m.positions.size());
  // Faces in three spellings: plain, v/vt/vn, and negative (relative to the vertex count).
  for (std::size_t f = 0; f < m.triangles.size(); ++f) {
    const Triangle& t = m.triangles[f];
    obj += 'f';
    for (int k = 0; k < 3; ++k) {
      obj += ' ';
      if (f % 3 == 0) num(static_cast<std::int64_t>(t[k]) + 1);
      else if (f % 3 == 1) num(static_cast<std::int64_t>(t[k]) + 1), obj += "/1/1";
      else num(static_cast<std::int64_t>(t[k]) - nv);
    }
    obj += (f % 5 == 0) ? "  # a comment\n" : "\n";
  }
  ASSERT_GT(obj.size(), std::size_t{8} << 20);
  ScratchDir dir;
  const io::Asset a = io::load_asset(dir.write("big.obj", obj), {.weld_tolerance = 0.0f});
  ASSERT_EQ(a.input_positions.size(), m.positions.size());
  ASSERT_EQ(a.input_triangles.size(), m.triangles.size());
  for (std::size_t i = 0; i < m.positions.size(); ++i) ASSERT_EQ(a.input_positions[i], m.positions[i]) << i;
  for (std::size_t f = 0; f < m.triangles.size(); ++f) ASSERT_EQ(a.input_triangles[f], m.triangles[f]) << f;
}

TEST(LargeRead, ObjErrorInALaterChunkNamesItsLine) {
  std::string obj;
  for (int i = 0; i < 600000; ++i) obj += "v 0.25 0.5 0.75\n";
  obj += "f 1 2 3\nv 1 2 x\n";
  ASSERT_GT(obj.size(), std::size_t{8} << 20);  // two chunks, the error in the second
  ScratchDir dir;
  const std::string path = dir.write("bad.obj", obj);
  test::expect_input_error([&] { io::load_asset(path); }, path, "line 600002: expected coordinate 3 of vertex 600001");
}

TEST(LargeRead, BinaryPlyRoundTripsPositionsAndValues) {
  const Mesh& m = big_mesh();
  io::Asset a;
  a.path = "big";
  a.input_positions = m.positions;
  a.input_triangles = m.triangles;
  a.mesh = m;
  a.input_to_welded.resize(m.positions.size());
  for (std::uint32_t i = 0; i < a.input_to_welded.size(); ++i) a.input_to_welded[i] = i;
  SdfField field;
  field.values.resize(m.positions.size());
  for (std::size_t i = 0; i < field.values.size(); ++i) field.values[i] = 0.5f + m.positions[i].x;
  ScratchDir dir;
  const std::string path = dir.path("big.ply");
  io::write_field(path, a, field);  // float xyz, quality, rgb: the general row path
  const io::FieldFile back = io::read_field(path, io::ValuesRequired::Yes, {.weld_tolerance = 0.0f});
  ASSERT_EQ(back.asset.input_positions, m.positions);
  ASSERT_EQ(back.asset.input_triangles, m.triangles);
  ASSERT_EQ(back.values, field.values);
}

// Binary face rows "3 a b c" are decoded on all threads, 13 bytes apart; a row that is not
// (a quad late in the file, an index out of range) sends the element to the sequential reader,
// with the same result and error as before.
TEST(LargeRead, BinaryPlyFaceRowsInParallelAndTheirFallback) {
  constexpr std::uint32_t kVertices = 1000, kFaces = 150000, kOdd = 140000;
  const auto ply = [&](std::uint32_t odd_corners, std::uint32_t odd_index) {
    std::string s = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(kVertices) +
                    "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                    std::to_string(kFaces) + "\nproperty list uchar int vertex_indices\nend_header\n";
    for (std::uint32_t v = 0; v < kVertices; ++v) {
      const float p[3] = {static_cast<float>(v), static_cast<float>(v % 7), static_cast<float>(v % 13)};
      s.append(reinterpret_cast<const char*>(p), sizeof p);
    }
    for (std::uint32_t f = 0; f < kFaces; ++f) {
      const std::uint32_t n = f == kOdd ? odd_corners : 3;
      s += static_cast<char>(n);
      for (std::uint32_t k = 0; k < n; ++k) {
        const std::uint32_t v = f == kOdd && k == 1 ? odd_index : (f + k * 17) % kVertices;
        s.append(reinterpret_cast<const char*>(&v), sizeof v);
      }
    }
    return s;
  };
  const auto expected = [&](std::uint32_t f, std::uint32_t k) { return (f + k * 17) % kVertices; };
  ScratchDir dir;
  const io::Asset plain = io::load_asset(dir.write("plain.ply", ply(3, expected(kOdd, 1))), {.weld_tolerance = 0.0f});
  ASSERT_EQ(plain.input_triangles.size(), kFaces);
  for (std::uint32_t f = 0; f < kFaces; ++f)
    for (std::uint32_t k = 0; k < 3; ++k) ASSERT_EQ(plain.input_triangles[f][k], expected(f, k)) << f;

  const io::Asset quad = io::load_asset(dir.write("quad.ply", ply(4, expected(kOdd, 1))), {.weld_tolerance = 0.0f});
  ASSERT_EQ(quad.input_triangles.size(), kFaces + 1);  // the quad as a fan of two
  EXPECT_EQ(quad.input_triangles[kOdd - 1], plain.input_triangles[kOdd - 1]);
  EXPECT_EQ(quad.input_triangles[kOdd + 1], (Triangle{expected(kOdd, 0), expected(kOdd, 2), expected(kOdd, 3)}));
  EXPECT_EQ(quad.input_triangles[kOdd + 2], plain.input_triangles[kOdd + 1]);

  const std::string bad = dir.write("bad.ply", ply(3, kVertices));
  test::expect_input_error([&] { io::load_asset(bad); }, bad,
                           "face " + std::to_string(kOdd) + " uses vertex " + std::to_string(kVertices));
}

// A mesh that cannot fit is refused from the counts, before its arrays are allocated: the
// limit here is SDFKIT_MEMORY_LIMIT (as on a machine with 1 MB free).
TEST(LargeRead, AMeshTooLargeForMemoryIsRefusedFromItsCounts) {
  const Mesh& m = big_mesh();
  io::Asset a;
  a.input_positions = m.positions;
  a.input_triangles = m.triangles;
  a.mesh = m;
  a.input_to_welded.resize(m.positions.size());
  for (std::uint32_t i = 0; i < a.input_to_welded.size(); ++i) a.input_to_welded[i] = i;
  SdfField field;
  field.values.assign(m.positions.size(), 1.0f);
  ScratchDir dir;
  const std::string ply = dir.path("big.ply");
  io::write_field(ply, a, field);
  std::string obj;
  for (int i = 0; i < 20000; ++i) obj += "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n";
  const std::string obj_path = dir.write("big.obj", obj);
  ASSERT_NO_THROW(io::load_asset(ply));
  ASSERT_EQ(setenv("SDFKIT_MEMORY_LIMIT", "1000000", 1), 0);
  test::expect_input_error([&] { io::load_asset(ply); }, ply,
                           "a mesh of 163842 vertices and 327680 triangles needs about");
  test::expect_input_error([&] { io::load_asset(obj_path); }, obj_path,
                           "a mesh of 60000 vertices and 20000 triangles needs about");
  unsetenv("SDFKIT_MEMORY_LIMIT");
  EXPECT_NO_THROW(io::load_asset(obj_path));
}

// A 50M-triangle mesh (25M vertices): with 24 GiB available it is estimated to fit (about
// 10.6 GiB); with 8 GiB a file of that size (sparse: a header, then a hole of the binary data's
// exact length, so that it is not refused as truncated first) is refused from its header's
// counts, before anything is allocated or read.
TEST(LargeRead, FiftyMillionTrianglesFitIn24GiBAndAreRefusedIn8) {
  ScratchDir dir;
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 25000000\nproperty float x\nproperty float y\n"
      "property float z\nelement face 50000000\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string ply = dir.write("huge.ply", header);
  std::filesystem::resize_file(ply, header.size() + 25000000ull * 12 + 50000000ull * 13);
  ASSERT_EQ(setenv("SDFKIT_MEMORY_LIMIT", "25769803776", 1), 0);  // 24 GiB
  EXPECT_NO_THROW(io::detail::check_mesh_fits(ply, 25000000, 50000000));
  ASSERT_EQ(setenv("SDFKIT_MEMORY_LIMIT", "8589934592", 1), 0);  // 8 GiB
  test::expect_input_error([&] { io::load_asset(ply); }, ply,
                           "a mesh of 25000000 vertices and 50000000 triangles needs about 10.6 GiB");
  unsetenv("SDFKIT_MEMORY_LIMIT");
}

}  // namespace
}  // namespace sdfkit

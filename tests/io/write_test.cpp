// Writers: glTF write-back and fresh glTF, PLY, txt; round trips through every format; the
// colour map; atomic replacement.

#include "sdfkit/core/log.hpp"
#include "sdfkit/io/asset.hpp"

#include "gltf_builder.hpp"
#include "io_test_util.hpp"
#include "log_capture.hpp"

#include <gtest/gtest.h>
#include <tiny_gltf.h>
#include <glm/geometric.hpp>

#include <algorithm>
#include <charconv>
#include <sstream>

namespace sdfkit {
namespace {

io::WriteOptions write_options(bool color, bool normalized) {
  io::WriteOptions o;
  o.color = color;
  o.normalized = normalized;
  return o;
}

using test::GltfBuilder;
using test::ScratchDir;
using test::LogCapture;
using test::kCubeOff;
using test::ramp_field;

// The value the writers must put on input vertex `v`.
float vertex_value(const io::Asset& a, const SdfField& f, std::size_t v) {
  return f.values[a.input_to_welded[v]];
}

// --- glTF inspection with tinygltf -------------------------------------------------------

bool keep_bytes(tinygltf::Image* image, int, std::string*, std::string*, int, int,
                const unsigned char* bytes, int size, void*) {
  image->image.assign(bytes, bytes + size);
  return true;
}

tinygltf::Model load_model(const std::string& path) {
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&keep_bytes, nullptr);
  tinygltf::Model m;
  std::string err, warn;
  const bool glb = path.size() > 4 && path.substr(path.size() - 4) == ".glb";
  const bool ok = glb ? loader.LoadBinaryFromFile(&m, &err, &warn, path)
                      : loader.LoadASCIIFromFile(&m, &err, &warn, path);
  EXPECT_TRUE(ok) << err;
  return m;
}

// Tightly packed float accessor data (what sdfkit writes).
std::vector<float> floats_of(const tinygltf::Model& m, int accessor) {
  const tinygltf::Accessor& a = m.accessors.at(static_cast<std::size_t>(accessor));
  EXPECT_EQ(a.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
  const tinygltf::BufferView& v = m.bufferViews.at(static_cast<std::size_t>(a.bufferView));
  EXPECT_EQ(v.byteStride, 0u);
  EXPECT_EQ(v.byteOffset % 4, 0u);
  const int comps = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type));
  std::vector<float> out(a.count * static_cast<std::size_t>(comps));
  const auto& data = m.buffers.at(static_cast<std::size_t>(v.buffer)).data;
  EXPECT_LE(v.byteOffset + a.byteOffset + out.size() * 4, data.size());
  std::memcpy(out.data(), data.data() + v.byteOffset + a.byteOffset, out.size() * 4);
  return out;
}

// An input glTF with what write-back must keep: a material with a texture whose images are an
// undecodable data URI and an external file, UVs, an existing COLOR_0, a node hierarchy with
// two instances of one mesh, and an external .bin buffer.
struct TexturedInput {
  std::string path;
  std::string image0_bytes = "not really a PNG \x01\x02\x03";
  std::string image1_bytes = "JPEG? no \xff\xd8";
};

TexturedInput write_textured_input(const ScratchDir& dir) {
  TexturedInput in;
  GltfBuilder b;
  // Two triangles forming a quad with a UV seam along the diagonal: 6 vertices, 4 positions.
  const int pos = b.positions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0});
  std::string uv, col;
  for (float f : {0.f, 0.f, 1.f, 0.f, 1.f, 1.f, 0.5f, 0.f, 1.f, 1.f, 0.f, 1.f}) test::put(uv, f);
  for (int i = 0; i < 18; ++i) test::put(col, 0.5f);
  const int uva = b.accessor(b.view(uv, 0, 34962), 0, 5126, 6, "VEC2");
  const int cola = b.accessor(b.view(col, 0, 34962), 0, 5126, 6, "VEC3");
  b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(pos) + ",\"TEXCOORD_0\":" +
         std::to_string(uva) + ",\"COLOR_0\":" + std::to_string(cola) + "},\"material\":0}");
  b.node("{\"name\":\"root\",\"mesh\":0,\"children\":[1]}");
  b.node("{\"name\":\"child\",\"mesh\":0,\"translation\":[0,0,3]}");
  b.extra(
      "\"materials\":[{\"name\":\"painted\",\"pbrMetallicRoughness\":{\"baseColorTexture\":"
      "{\"index\":0}},\"emissiveTexture\":{\"index\":1}}]");
  b.extra("\"textures\":[{\"source\":0,\"sampler\":0},{\"source\":1}]");
  b.extra("\"samplers\":[{\"magFilter\":9728}]");
  b.extra("\"images\":[{\"uri\":\"data:image/png;base64," + test::base64_encode(in.image0_bytes) +
          "\"},{\"uri\":\"tex.jpg\"}]");
  dir.write("quad.bin", b.bin());
  dir.write("tex.jpg", in.image1_bytes);
  in.path = dir.write("quad.gltf", b.json("quad.bin", "\"scene\":0,\"scenes\":[{\"nodes\":[0]}]"));
  return in;
}

class WriteGltfBack : public ::testing::TestWithParam<std::string> {};

TEST_P(WriteGltfBack, KeepsTheModelAndAddsSdfAttributes) {
  ScratchDir dir;
  const TexturedInput in = write_textured_input(dir);
  const io::Asset a = io::load_asset(in.path);
  ASSERT_EQ(a.input_positions.size(), 12u);  // two instances of 6 vertices
  EXPECT_EQ(a.mesh.positions.size(), 8u);    // 4 corners per instance
  const SdfField field = ramp_field(a, SdfDomain::Vertex);

  // Into another directory: the output must not depend on files next to the input.
  std::filesystem::create_directory(dir.path("out"));
  const std::string out = dir.path("out/result." + GetParam());
  LogCapture warnings;
  io::write_field(out, a, field);
  const std::vector<std::string> logged = warnings.messages();
  ASSERT_EQ(logged.size(), 1u);
  // The mesh and its copy for the second instance (whose ramp values differ) both had COLOR_0.
  EXPECT_NE(logged[0].find("replaced the existing COLOR_0 of 2 primitives"), std::string::npos);
  EXPECT_EQ(std::vector<std::string>{"result." + GetParam()}, [&] {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir.path("out")))
      names.push_back(e.path().filename().string());
    return names;
  }());

  // sdfkit reads back the same geometry.
  const io::Asset back = io::load_asset(out);
  EXPECT_EQ(back.input_positions, a.input_positions);
  EXPECT_EQ(back.input_triangles, a.input_triangles);

  // tinygltf sees the preserved model and the new attributes.
  const tinygltf::Model m = load_model(out);
  ASSERT_EQ(m.buffers.size(), 1u);
  ASSERT_EQ(m.nodes.size(), 2u);
  EXPECT_EQ(m.nodes[0].name, "root");
  EXPECT_EQ(m.nodes[0].children, std::vector<int>{1});
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "painted");
  EXPECT_EQ(m.materials[0].pbrMetallicRoughness.baseColorTexture.index, 0);
  EXPECT_EQ(m.materials[0].emissiveTexture.index, 1);
  ASSERT_EQ(m.textures.size(), 2u);
  EXPECT_EQ(m.textures[0].sampler, 0);
  ASSERT_EQ(m.images.size(), 2u);
  EXPECT_EQ(std::string(m.images[0].image.begin(), m.images[0].image.end()), in.image0_bytes);
  EXPECT_EQ(std::string(m.images[1].image.begin(), m.images[1].image.end()), in.image1_bytes);
  // The child node's values differ from the root's: it draws a copy of the mesh (same
  // POSITION and material) that carries its own.
  ASSERT_EQ(m.meshes.size(), 2u);
  EXPECT_EQ(m.nodes[0].mesh, 0);
  EXPECT_EQ(m.nodes[1].mesh, 1);
  {
    const tinygltf::Primitive& copy = m.meshes[1].primitives.at(0);
    EXPECT_EQ(copy.attributes.at("POSITION"), m.meshes[0].primitives.at(0).attributes.at("POSITION"));
    EXPECT_EQ(copy.material, 0);
    const std::vector<float> sdf1 = floats_of(m, copy.attributes.at("_SDF"));
    ASSERT_EQ(sdf1.size(), 6u);
    for (std::size_t v = 0; v < 6; ++v) EXPECT_EQ(sdf1[v], vertex_value(a, field, v + 6));
  }
  const tinygltf::Primitive& prim = m.meshes[0].primitives.at(0);
  EXPECT_EQ(prim.material, 0);
  for (const char* name : {"POSITION", "TEXCOORD_0", "COLOR_0", "_SDF", "_SDF_NORMALIZED"})
    EXPECT_EQ(prim.attributes.count(name), 1u) << name;
  const std::vector<float> sdf = floats_of(m, prim.attributes.at("_SDF"));
  const std::vector<float> norm = floats_of(m, prim.attributes.at("_SDF_NORMALIZED"));
  const std::vector<float> rgb = floats_of(m, prim.attributes.at("COLOR_0"));
  EXPECT_EQ(m.accessors[static_cast<std::size_t>(prim.attributes.at("COLOR_0"))].type,
            TINYGLTF_TYPE_VEC3);
  ASSERT_EQ(sdf.size(), 6u);
  const std::vector<float> all_norm = normalized(field.values);
  for (std::size_t v = 0; v < 6; ++v) {  // the first instance's values
    EXPECT_EQ(sdf[v], vertex_value(a, field, v));
    EXPECT_EQ(norm[v], all_norm[a.input_to_welded[v]]);
    const glm::vec3 c = io::colormap(norm[v]);
    EXPECT_EQ(rgb[3 * v], c.x);
    EXPECT_EQ(rgb[3 * v + 1], c.y);
    EXPECT_EQ(rgb[3 * v + 2], c.z);
  }
  // Seam vertices (same position, different UVs) carry the same value.
  EXPECT_EQ(sdf[0], sdf[3]);
  EXPECT_EQ(sdf[2], sdf[4]);
}

INSTANTIATE_TEST_SUITE_P(Containers, WriteGltfBack, ::testing::Values("glb", "gltf"));

TEST(WriteGltf, MissingImageFileIsAWarningAndKeepsItsUri) {
  GltfBuilder b;
  const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(pos) + "}}");
  b.node("{\"mesh\":0}");
  b.extra("\"images\":[{\"uri\":\"textures/missing.png\"}],\"textures\":[{\"source\":0}]");
  ScratchDir dir;
  const std::string in =
      dir.write("tri.gltf", b.data_uri_gltf("\"scene\":0,\"scenes\":[{\"nodes\":[0]}]"));
  LogCapture warnings;
  const io::Asset a = io::load_asset(in);
  EXPECT_TRUE(std::any_of(a.warnings.begin(), a.warnings.end(), [](const std::string& w) {
    return w.find("missing.png") != std::string::npos;
  }));
  const std::string out = dir.path("tri.glb");
  io::write_field(out, a, ramp_field(a, SdfDomain::Vertex));
  const tinygltf::Model m = load_model(out);
  ASSERT_EQ(m.images.size(), 1u);
  EXPECT_EQ(m.images[0].uri, "textures/missing.png");
}

TEST(WriteGltf, WithoutColorKeepsTheInputColors) {
  ScratchDir dir;
  const io::Asset a = io::load_asset(write_textured_input(dir).path);
  const std::string out = dir.path("plain.glb");
  io::write_field(out, a, ramp_field(a, SdfDomain::Vertex), write_options(false, false));
  const tinygltf::Model m = load_model(out);
  const std::vector<float> rgb = floats_of(m, m.meshes[0].primitives[0].attributes.at("COLOR_0"));
  for (float c : rgb) EXPECT_EQ(c, 0.5f);
}

TEST(WriteGltf, FreshModelFromOff) {
  ScratchDir dir;
  const io::Asset a = io::load_asset(dir.write("cube.off", kCubeOff));
  const SdfField field = ramp_field(a, SdfDomain::Vertex);
  for (const char* ext : {"glb", "gltf"}) {
    const std::string out = dir.path(std::string("cube.") + ext);
    io::write_field(out, a, field);
    const io::Asset back = io::load_asset(out);
    EXPECT_EQ(back.input_positions, a.input_positions);
    EXPECT_EQ(back.input_triangles, a.input_triangles);
    const tinygltf::Model m = load_model(out);
    ASSERT_EQ(m.meshes.size(), 1u);
    const tinygltf::Primitive& prim = m.meshes[0].primitives.at(0);
    const tinygltf::Accessor& pos =
        m.accessors[static_cast<std::size_t>(prim.attributes.at("POSITION"))];
    EXPECT_EQ(pos.minValues, (std::vector<double>{0, 0, 0}));
    EXPECT_EQ(pos.maxValues, (std::vector<double>{1, 1, 1}));
    const std::vector<float> sdf = floats_of(m, prim.attributes.at("_SDF"));
    ASSERT_EQ(sdf.size(), 8u);
    for (std::size_t v = 0; v < 8; ++v) EXPECT_EQ(sdf[v], vertex_value(a, field, v));
    EXPECT_EQ(floats_of(m, prim.attributes.at("COLOR_0")).size(), 24u);
  }
}

TEST(WriteGltf, PerFaceValuesAreRejected) {
  ScratchDir dir;
  const io::Asset a = io::load_asset(dir.write("cube.off", kCubeOff));
  const std::string out = dir.path("faces.glb");
  test::expect_input_error([&] { io::write_field(out, a, ramp_field(a, SdfDomain::Face)); }, out,
                           "per-face values cannot be stored in glTF; write .ply or .txt");
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(WriteField, MismatchedFieldAndUnsupportedFormatsAreErrors) {
  ScratchDir dir;
  const io::Asset a = io::load_asset(dir.write("cube.off", kCubeOff));
  SdfField f = ramp_field(a, SdfDomain::Vertex);
  f.values.pop_back();
  const std::string out = dir.path("short.txt");
  test::expect_input_error([&] { io::write_field(out, a, f); }, out,
                           "the field has 7 values but the mesh has 8 vertices");
  const std::string off = dir.path("values.off");
  test::expect_input_error([&] { io::write_field(off, a, ramp_field(a, SdfDomain::Vertex)); }, off,
                           "cannot store values in .off");
  // An output's formats, not a mesh's: .txt is one, .obj and .off are not.
  for (const char* name : {"values.xyz", "values"}) {
    const std::string bad = dir.path(name);
    test::expect_input_error([&] { io::check_output(bad, SdfDomain::Vertex); }, bad,
                             "; write .gltf, .glb, .ply or .txt");
    EXPECT_FALSE(std::filesystem::exists(bad));
  }
  test::expect_input_error([&] { io::check_output(dir.path("v.xyz"), SdfDomain::Vertex); }, dir.path("v.xyz"),
                           "unknown extension '.xyz'");
  test::expect_input_error([&] { io::check_output(dir.path("v"), SdfDomain::Vertex); }, dir.path("v"),
                           "no file extension");
  EXPECT_NO_THROW(io::check_output(dir.path("v.TXT"), SdfDomain::Face));
}

// --- PLY --------------------------------------------------------------------------------

struct ParsedPly {
  std::string header;
  std::vector<glm::vec3> positions;
  std::vector<float> vertex_quality, face_quality;
  std::vector<std::array<std::uint8_t, 3>> colors;
  std::vector<Triangle> triangles;
};

// Parses exactly the layout write_field produces (binary little endian).
ParsedPly parse_sdfkit_ply(const std::string& bytes, bool per_vertex, bool color) {
  ParsedPly p;
  const std::size_t end = bytes.find("end_header\n");
  EXPECT_NE(end, std::string::npos);
  p.header = bytes.substr(0, end);
  std::size_t pos = end + 11;
  auto take = [&](auto& value) {
    std::memcpy(&value, bytes.data() + pos, sizeof(value));
    pos += sizeof(value);
  };
  auto count_of = [&](const std::string& element) {
    const std::size_t at = p.header.find("element " + element + " ");
    return std::stoul(p.header.substr(at + 9 + element.size()));
  };
  const std::size_t nv = count_of("vertex"), nf = count_of("face");
  for (std::size_t v = 0; v < nv; ++v) {
    glm::vec3 x;
    take(x.x), take(x.y), take(x.z);
    p.positions.push_back(x);
    if (per_vertex) {
      float q;
      take(q);
      p.vertex_quality.push_back(q);
      if (color) {
        std::array<std::uint8_t, 3> c;
        take(c);
        p.colors.push_back(c);
      }
    }
  }
  for (std::size_t f = 0; f < nf; ++f) {
    std::uint8_t n;
    take(n);
    EXPECT_EQ(n, 3);
    Triangle t;
    for (auto& i : t) {
      std::int32_t k;
      take(k);
      i = static_cast<std::uint32_t>(k);
    }
    p.triangles.push_back(t);
    if (!per_vertex) {
      float q;
      take(q);
      p.face_quality.push_back(q);
      if (color) {
        std::array<std::uint8_t, 3> c;
        take(c);
        p.colors.push_back(c);
      }
    }
  }
  EXPECT_EQ(pos, bytes.size());
  return p;
}

TEST(WritePly, PerVertexQualityAndColors) {
  ScratchDir dir;
  // The seam quad of the glTF test, through OBJ with duplicated vertices.
  const io::Asset a = io::load_asset(dir.write(
      "quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 4 5 6\n"));
  const SdfField field = ramp_field(a, SdfDomain::Vertex);
  const std::string out = dir.path("quad.ply");
  io::write_field(out, a, field);
  const ParsedPly p = parse_sdfkit_ply(test::read_bytes(out), true, true);
  EXPECT_NE(p.header.find("format binary_little_endian 1.0"), std::string::npos);
  EXPECT_NE(p.header.find("property float quality\nproperty uchar red"), std::string::npos);
  EXPECT_EQ(p.positions, a.input_positions);
  EXPECT_EQ(p.triangles, a.input_triangles);
  const std::vector<float> norm = normalized(field.values);
  for (std::size_t v = 0; v < 6; ++v) {
    EXPECT_EQ(p.vertex_quality[v], vertex_value(a, field, v));
    const glm::vec3 c = io::colormap(norm[a.input_to_welded[v]]);
    EXPECT_EQ(p.colors[v][0], static_cast<std::uint8_t>(std::lround(c.x * 255)));
    EXPECT_EQ(p.colors[v][2], static_cast<std::uint8_t>(std::lround(c.z * 255)));
  }
  EXPECT_EQ(p.colors[0], (std::array<std::uint8_t, 3>{255, 0, 0}));  // lowest value: red
  EXPECT_EQ(p.colors[5], (std::array<std::uint8_t, 3>{0, 0, 255}));  // highest: blue

  // sdfkit reads its own PLY back.
  const io::Asset back = io::load_asset(out);
  EXPECT_EQ(back.input_positions, a.input_positions);
  EXPECT_EQ(back.input_triangles, a.input_triangles);
}

TEST(WritePly, PerFaceNormalizedWithoutColor) {
  ScratchDir dir;
  const io::Asset a = io::load_asset(dir.write("cube.off", kCubeOff));
  const SdfField field = ramp_field(a, SdfDomain::Face);
  const std::string out = dir.path("faces.PLY");
  io::write_field(out, a, field, write_options(false, true));
  const ParsedPly p = parse_sdfkit_ply(test::read_bytes(out), false, false);
  EXPECT_EQ(p.header.find("red"), std::string::npos);
  EXPECT_NE(p.header.find("property list uchar int vertex_indices\nproperty float quality"),
            std::string::npos);
  EXPECT_EQ(p.face_quality, normalized(field.values));
  EXPECT_EQ(p.face_quality.front(), 0.0f);
  EXPECT_EQ(p.face_quality.back(), 1.0f);
}

// --- txt --------------------------------------------------------------------------------

std::vector<float> parse_lines(const std::string& text) {
  std::vector<float> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    float v = 0;
    const auto [ptr, ec] = std::from_chars(line.data(), line.data() + line.size(), v);
    EXPECT_TRUE(ec == std::errc() && ptr == line.data() + line.size()) << line;
    out.push_back(v);
  }
  return out;
}

TEST(WriteTxt, OneValuePerInputVertexOrFaceExactly) {
  ScratchDir dir;
  const io::Asset a = io::load_asset(dir.write(
      "quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 4 5 6\n"));
  SdfField field = ramp_field(a, SdfDomain::Vertex);
  field.values[1] = 1.0f / 3.0f;  // needs all 9 significant digits
  io::write_field(dir.path("v.txt"), a, field);
  const std::vector<float> v = parse_lines(test::read_bytes(dir.path("v.txt")));
  ASSERT_EQ(v.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(v[i], vertex_value(a, field, i));

  io::write_field(dir.path("n.txt"), a, field, write_options(true, true));
  const std::vector<float> n = parse_lines(test::read_bytes(dir.path("n.txt")));
  const std::vector<float> expected = normalized(field.values);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(n[i], expected[a.input_to_welded[i]]);

  const SdfField faces = ramp_field(a, SdfDomain::Face);
  io::write_field(dir.path("f.txt"), a, faces);
  EXPECT_EQ(parse_lines(test::read_bytes(dir.path("f.txt"))), faces.values);
}

// --- round trips through every format ---------------------------------------------------

TEST(RoundTrip, EveryInputFormatThroughEveryMeshOutput) {
  ScratchDir dir;
  std::vector<std::string> inputs = {dir.write("cube.off", kCubeOff)};
  {
    const io::Asset cube = io::load_asset(inputs[0]);
    std::ostringstream obj, ply;
    for (const auto& p : cube.input_positions)
      obj << "v " << p.x << ' ' << p.y << ' ' << p.z << "\n";
    for (const auto& t : cube.input_triangles)
      obj << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << "\n";
    inputs.push_back(dir.write("cube.obj", obj.str()));
    ply << "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
           "property float z\nelement face 12\nproperty list uchar int "
           "vertex_indices\nend_header\n";
    for (const auto& p : cube.input_positions) ply << p.x << ' ' << p.y << ' ' << p.z << "\n";
    for (const auto& t : cube.input_triangles)
      ply << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << "\n";
    inputs.push_back(dir.write("cube_ascii.ply", ply.str()));
    inputs.push_back(write_textured_input(dir).path);
  }
  for (const std::string& input : inputs) {
    const io::Asset a = io::load_asset(input);
    const SdfField field = ramp_field(a, SdfDomain::Vertex);
    for (const char* ext : {"ply", "glb", "gltf"}) {
      const std::string out = input + ".out." + ext;
      io::write_field(out, a, field, write_options(false, false));
      const io::Asset back = io::load_asset(out);
      EXPECT_EQ(back.input_positions, a.input_positions) << out;
      EXPECT_EQ(back.input_triangles, a.input_triangles) << out;
      EXPECT_EQ(back.input_to_welded, a.input_to_welded) << out;
    }
    io::write_field(input + ".out.txt", a, field);
    EXPECT_EQ(parse_lines(test::read_bytes(input + ".out.txt")).size(), a.input_positions.size());
  }
}

// --- colour map -------------------------------------------------------------------------

TEST(Colormap, RedToBlueThroughYellowGreenCyanAndContinuous) {
  EXPECT_EQ(io::colormap(0.0f), glm::vec3(1, 0, 0));
  EXPECT_EQ(io::colormap(0.25f), glm::vec3(1, 1, 0));
  EXPECT_EQ(io::colormap(0.5f), glm::vec3(0, 1, 0));
  EXPECT_EQ(io::colormap(0.75f), glm::vec3(0, 1, 1));
  EXPECT_EQ(io::colormap(1.0f), glm::vec3(0, 0, 1));
  EXPECT_EQ(io::colormap(-3.0f), io::colormap(0.0f));
  EXPECT_EQ(io::colormap(7.0f), io::colormap(1.0f));
  EXPECT_EQ(io::colormap(std::nanf("")), io::colormap(0.0f));
  glm::vec3 prev = io::colormap(0.0f);
  for (int i = 1; i <= 1000; ++i) {
    const glm::vec3 c = io::colormap(static_cast<float>(i) / 1000.0f);
    EXPECT_LE(glm::length(c - prev), 0.0058f) << i;  // 4/1000 per channel step at most
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(c[k] >= 0.0f && c[k] <= 1.0f);
    prev = c;
  }
}

// --- atomic writes ----------------------------------------------------------------------

TEST(AtomicWrite, FailingWriterLeavesTheOldFileAndNoTemporary) {
  ScratchDir dir;
  const std::string path = dir.write("values.txt", "old content\n");
  EXPECT_THROW(io::write_file_atomically(path,
                                         [](std::ostream& out) {
                                           out << "half of the new cont";
                                           throw std::runtime_error("writer failed");
                                         }),
               std::runtime_error);
  EXPECT_EQ(test::read_bytes(path), "old content\n");
  EXPECT_EQ(dir.files(), std::vector<std::string>{"values.txt"});

  io::write_file_atomically(path, [](std::ostream& out) { out << "new content\n"; });
  EXPECT_EQ(test::read_bytes(path), "new content\n");
  EXPECT_EQ(dir.files(), std::vector<std::string>{"values.txt"});
}

TEST(AtomicWrite, NewFileIsNotCreatedWhenTheWriterFails) {
  ScratchDir dir;
  const std::string path = dir.path("never.ply");
  EXPECT_THROW(io::write_file_atomically(path, [](std::ostream&) { throw InputError("bad"); }),
               InputError);
  EXPECT_TRUE(dir.files().empty());
}

TEST(AtomicWrite, UnwritablePlacesAreOneLineErrors) {
  ScratchDir dir;
  const std::string missing_dir = dir.path("no/such/dir/out.txt");
  try {
    io::write_file_atomically(missing_dir, [](std::ostream& out) { out << "x"; });
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(missing_dir + ": ", 0), 0u) << e.what();
  }
  std::filesystem::create_directory(dir.path("folder.txt"));
  EXPECT_THROW(
      io::write_file_atomically(dir.path("folder.txt"), [](std::ostream& out) { out << "x"; }),
      Error);
  EXPECT_EQ(dir.files(), std::vector<std::string>{"folder.txt"});
}

}  // namespace
}  // namespace sdfkit

// Untrusted assets (SECURITY.md): a glTF reads external buffers and images only inside its own
// directory, and refuses the rest without opening it or telling anything about it; the
// resource limits refuse an asset as soon as a count is known.

#include "sdfkit/io/asset.hpp"

#include "gltf_builder.hpp"
#include "io_test_util.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace sdfkit {
namespace {

namespace fs = std::filesystem;
using test::expect_input_error;
using test::GltfBuilder;
using test::ScratchDir;
using Strings = std::vector<std::string>;

const std::string kScene0 = "\"scene\":0,\"scenes\":[{\"nodes\":[0]}]";

// A tetrahedron in one buffer: 4 vertices, 4 triangles.
GltfBuilder tetra() {
  GltfBuilder b;
  const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1});
  const int idx = b.indices(std::vector<std::uint16_t>{0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3});
  b.mesh("{\"attributes\":{\"POSITION\":" + std::to_string(pos) +
         "},\"indices\":" + std::to_string(idx) + "}");
  b.node("{\"mesh\":0}");
  return b;
}

// The glTF text with the buffer at `uri`, its byteLength replaced by `byte_length`.
std::string with_buffer(const GltfBuilder& b, const std::string& uri, std::size_t byte_length) {
  std::string j = b.json(uri, kScene0);
  const std::string from = "\"byteLength\":" + std::to_string(b.bin().size()) + ",\"uri\"";
  const auto at = j.find(from);
  EXPECT_NE(at, std::string::npos);
  j.replace(at, from.size(), "\"byteLength\":" + std::to_string(byte_length) + ",\"uri\"");
  return j;
}

// root/secret.bin (outside, the right size to load as the buffer), root/assets/ (the asset's
// directory) with cube.bin, sub/cube.bin, an in-directory link and two links leading out.
class Untrusted : public ::testing::Test {
protected:
  void SetUp() override {
    secret_ = dir_.write("secret.bin", b_.bin());
    dir_.write("secret.png", "\x89PNG secret image bytes");
    fs::create_directories(assets_ / "sub");
    dir_.write("assets/cube.bin", b_.bin());
    dir_.write("assets/sub/cube.bin", b_.bin());
    fs::create_symlink("cube.bin", assets_ / "inlink.bin");
    fs::create_symlink("../secret.bin", assets_ / "link.bin");
    fs::create_symlink("..", assets_ / "up");
    fs::create_symlink(dir_.dir(), assets_ / "abs");
  }

  std::string asset(const std::string& name, const std::string& text) {
    return dir_.write("assets/" + name, text);
  }
  // The message load_asset throws for `path` ("" when it loads).
  static std::string error_of(const std::string& path, const io::LoadOptions& o = {}) {
    try {
      io::load_asset(path, o);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }

  GltfBuilder b_ = tetra();
  ScratchDir dir_;
  fs::path assets_ = dir_.dir() / "assets";
  std::string secret_;
};

TEST_F(Untrusted, DefaultsAreSafe) {
  const io::LoadOptions o;
  EXPECT_FALSE(o.allow_external_paths);
  EXPECT_EQ(o.max_triangles, io::kDefaultMaxTriangles);
  EXPECT_EQ(o.max_file_size, io::kDefaultMaxFileSize);
  EXPECT_GT(o.max_triangles, 0u);
  EXPECT_GT(o.max_file_size, 0u);
}

TEST_F(Untrusted, ParentEscapesAreRefused) {
  const std::size_t n = b_.bin().size();
  for (const std::string& uri :
       Strings{"../secret.bin", "sub/../../secret.bin", "./../secret.bin", "%2e%2e/secret.bin",
               "../../../../../../../../" + fs::path(secret_).relative_path().string()}) {
    const std::string p = asset("evil.gltf", with_buffer(b_, uri, n));
    expect_input_error([&] { io::load_asset(p); }, p, "leaves the asset's directory");
    EXPECT_NE(error_of(p).find("--allow-external-paths"), std::string::npos);
  }
}

TEST_F(Untrusted, TheIssuesEtcHostnameIsRefused) {
  std::error_code ec;
  const auto size = fs::file_size("/etc/hostname", ec);
  if (ec) GTEST_SKIP() << "no /etc/hostname here";
  const std::string uri = "../../../../../../etc/hostname";
  const std::string p = asset("evil.gltf", with_buffer(b_, uri, static_cast<std::size_t>(size)));
  expect_input_error([&] { io::load_asset(p); }, p, "'" + uri + "'");
}

TEST_F(Untrusted, AbsolutePathsAndSchemesAreRefused) {
  const std::size_t n = b_.bin().size();
  const std::string p = asset("abs.gltf", with_buffer(b_, secret_, n));
  expect_input_error([&] { io::load_asset(p); }, p, "'" + secret_ + "' is an absolute path");
  for (const std::string& uri : Strings{"file://" + secret_, "http://example.com/cube.bin", "C:/cube.bin",
                                "file:cube.bin"}) {
    const std::string q = asset("scheme.gltf", with_buffer(b_, uri, n));
    expect_input_error([&] { io::load_asset(q); }, q, "'" + uri + "' has a URI scheme");
  }
}

TEST_F(Untrusted, LinksLeadingOutAreRefused) {
  const std::size_t n = b_.bin().size();
  for (const std::string& uri : Strings{"link.bin", "up/secret.bin", "abs/secret.bin", "sub/../link.bin"}) {
    const std::string p = asset("links.gltf", with_buffer(b_, uri, n));
    expect_input_error([&] { io::load_asset(p); }, p, "'" + uri + "' leaves the asset's directory");
  }
}

TEST_F(Untrusted, ImagesAreConfinedToo) {
  // The buffer is fine (a data URI); only the texture's uri escapes. tinygltf would only warn
  // about an image it cannot read and the writer would embed one it could: refused instead.
  for (const std::string& uri : Strings{"../secret.png", secret_, "up/secret.png"}) {
    GltfBuilder b = tetra();
    b.extra("\"images\":[{\"uri\":\"" + uri + "\"}]");
    const std::string p = asset("image.gltf", b.data_uri_gltf(kScene0));
    expect_input_error([&] { io::load_asset(p); }, p, "'" + uri + "'");
  }
}

TEST_F(Untrusted, GlbExternalBuffersAreConfinedToo) {
  // The glb's JSON names an external buffer (a glb may, besides its BIN chunk).
  std::string json = b_.json("../secret.bin", kScene0);
  while (json.size() % 4) json += ' ';
  std::string bin = b_.bin();
  while (bin.size() % 4) bin += '\0';
  std::string out = "glTF";
  test::put<std::uint32_t>(out, 2);
  test::put<std::uint32_t>(out, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
  test::put<std::uint32_t>(out, static_cast<std::uint32_t>(json.size()));
  test::put<std::uint32_t>(out, 0x4E4F534A);
  out += json;
  test::put<std::uint32_t>(out, static_cast<std::uint32_t>(bin.size()));
  test::put<std::uint32_t>(out, 0x004E4942);
  out += bin;
  const std::string p = asset("evil.glb", out);
  expect_input_error([&] { io::load_asset(p); }, p, "'../secret.bin' leaves the asset's directory");
  io::LoadOptions allow;
  allow.allow_external_paths = true;
  EXPECT_EQ(io::load_asset(p, allow).input_triangles.size(), 4u);
}

TEST_F(Untrusted, RefusalsTellNothingAboutTheTarget) {
  // A wrong byteLength on an outside file: tinygltf would report the file's real size. The
  // message for an existing target, a missing one and one of another size is the same (bar
  // the name), and holds no size.
  const std::size_t real = b_.bin().size();
  dir_.write("big.bin", std::string(123457, 'x'));
  for (const std::string& form : Strings{"../", "up/", dir_.dir().string() + "/"}) {
    const std::string p = asset("a.gltf", "");
    const std::string shown = error_of(asset("a.gltf", with_buffer(b_, form + "secret.bin", 7)));
    const std::string missing = error_of(asset("a.gltf", with_buffer(b_, form + "nothere.bin", 7)));
    const std::string big = error_of(asset("a.gltf", with_buffer(b_, form + "big.bin", 7)));
    ASSERT_EQ(shown.rfind(p + ": ", 0), 0u) << shown;
    auto without = [](std::string s, const std::string& name) {
      s.replace(s.find(name), name.size(), "X");
      return s;
    };
    // (The asset's path and the URI are taken out first: a scratch directory's name has digits.)
    EXPECT_EQ(without(shown.substr(p.size()), form + "secret.bin").find(std::to_string(real)),
              std::string::npos)
        << shown;
    EXPECT_EQ(without(big.substr(p.size()), form + "big.bin").find("123457"), std::string::npos)
        << big;
    EXPECT_EQ(without(shown, "secret.bin"), without(missing, "nothere.bin"));
    EXPECT_EQ(without(shown, "secret.bin"), without(big, "big.bin"));
  }
}

TEST_F(Untrusted, FilesInsideTheDirectoryAndDataUrisKeepWorking) {
  const io::Asset reference = io::load_asset(asset("data.gltf", b_.data_uri_gltf(kScene0)));
  ASSERT_EQ(reference.input_triangles.size(), 4u);
  for (const std::string& uri : Strings{"cube.bin", "./cube.bin", "sub/cube.bin", "sub/../cube.bin",
                                "inlink.bin", "sub%2Fcube.bin", "up/assets/cube.bin"}) {
    const io::Asset a = io::load_asset(asset("ok.gltf", b_.json(uri, kScene0)));
    EXPECT_EQ(a.input_positions, reference.input_positions) << uri;
    EXPECT_EQ(a.input_triangles, reference.input_triangles) << uri;
  }
  // A missing file inside the directory is still a plain "not found".
  const std::string p = asset("missing.gltf", b_.json("absent.bin", kScene0));
  expect_input_error([&] { io::load_asset(p); }, p, "absent.bin");
  EXPECT_EQ(error_of(p).find("refused"), std::string::npos);
}

TEST_F(Untrusted, AllowExternalPathsLiftsTheConfinement) {
  io::LoadOptions allow;
  allow.allow_external_paths = true;
  const std::size_t n = b_.bin().size();
  for (const std::string& uri : Strings{"../secret.bin", "link.bin", "up/secret.bin", secret_}) {
    const io::Asset a = io::load_asset(asset("trusted.gltf", with_buffer(b_, uri, n)), allow);
    EXPECT_EQ(a.input_triangles.size(), 4u) << uri;
    EXPECT_EQ(a.input_positions[1], glm::vec3(1, 0, 0)) << uri;
  }
  // An outside image is read (and kept for the writer) when allowed.
  GltfBuilder b = tetra();
  b.extra("\"images\":[{\"uri\":\"../secret.png\"}]");
  EXPECT_EQ(error_of(asset("image.gltf", b.data_uri_gltf(kScene0)), allow), "");
}

// ---- resource limits ----

const std::string kCubeObj =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 3 4 8 7\nf 2 3 7 6\nf 1 5 8 4\n";
const std::string kCubePly =
    "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
    "property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
    "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n4 0 4 7 3\n";

TEST(Limits, MaxTrianglesRefusesEveryFormat) {
  ScratchDir dir;
  GltfBuilder b = tetra();
  const std::vector<std::pair<std::string, std::size_t>> files = {
      {dir.write("cube.off", test::kCubeOff), 12},
      {dir.write("cube.obj", kCubeObj), 12},
      {dir.write("cube.ply", kCubePly), 12},
      {dir.write("tetra.gltf", b.data_uri_gltf(kScene0)), 4},
      {dir.write("tetra.glb", b.glb(kScene0)), 4}};
  for (const auto& [path, triangles] : files) {
    io::LoadOptions o;
    o.max_triangles = triangles;
    EXPECT_EQ(io::load_asset(path, o).input_triangles.size(), triangles) << path;
    o.max_triangles = triangles - 1;
    expect_input_error([&] { io::load_asset(path, o); }, path,
                       "more than the limit of " + std::to_string(triangles - 1) + " triangles");
  }
}

TEST(Limits, DeclaredCountsAreRefusedBeforeTheyAreRead) {
  // The header's face count (6 faces, 12 triangles) is what passes a limit of 5: the message
  // counts faces, not triangles, because nothing past the header was read.
  ScratchDir dir;
  io::LoadOptions o;
  o.max_triangles = 5;
  for (const std::string& p : {dir.write("cube.off", test::kCubeOff), dir.write("cube.ply", kCubePly)})
    expect_input_error([&] { io::load_asset(p, o); }, p, "6 faces, more than the limit of 5");
  // Vertices: 8 > 3 x 2.
  o.max_triangles = 2;
  for (const std::string& p : {dir.path("cube.off"), dir.path("cube.ply")})
    expect_input_error([&] { io::load_asset(p, o); }, p, "8 vertices, more than the limit of 6");
  // A glTF mesh drawn by 100 nodes: 400 triangles from a 48-byte buffer; refused at the node
  // that passes the limit, before its accessors are read.
  GltfBuilder b = tetra();
  std::string nodes;
  for (int i = 0; i < 99; ++i) b.node("{\"mesh\":0,\"translation\":[" + std::to_string(i) + ",0,0]}");
  std::string roots;
  for (int i = 0; i < 100; ++i) roots += (i ? "," : "") + std::to_string(i);
  const std::string p =
      dir.write("instances.gltf", b.data_uri_gltf("\"scene\":0,\"scenes\":[{\"nodes\":[" + roots + "]}]"));
  o.max_triangles = 100;
  expect_input_error([&] { io::load_asset(p, o); }, p, "104 triangles, more than the limit of 100");
  o.max_triangles = 400;
  EXPECT_EQ(io::load_asset(p, o).input_triangles.size(), 400u);
}

TEST(Limits, MaxFileSizeRefusesTheAssetAndWhatItReferences) {
  ScratchDir dir;
  const std::string off = dir.write("cube.off", test::kCubeOff);
  io::LoadOptions o;
  o.max_file_size = test::kCubeOff.size();
  EXPECT_EQ(io::load_asset(off, o).input_triangles.size(), 12u);
  o.max_file_size = test::kCubeOff.size() - 1;
  expect_input_error([&] { io::load_asset(off, o); }, off,
                     "more than the limit of " + std::to_string(o.max_file_size));
  // A small .gltf whose external buffer is past the limit.
  GltfBuilder b = tetra();
  b.view(std::string(4000, '\0'));  // a buffer larger than the .gltf
  dir.write("tetra.bin", b.bin());
  const std::string gltf = dir.write("tetra.gltf", b.json("tetra.bin", kScene0));
  o.max_file_size = b.bin().size() - 1;
  ASSERT_LT(fs::file_size(gltf), o.max_file_size);
  expect_input_error([&] { io::load_asset(gltf, o); }, gltf,
                     "external file 'tetra.bin' has " + std::to_string(b.bin().size()) + " bytes");
  o.max_file_size = 0;  // no limit
  EXPECT_EQ(io::load_asset(gltf, o).input_triangles.size(), 4u);
}

}  // namespace
}  // namespace sdfkit

// The fuzz harnesses' committed inputs through the ordinary build (no fuzzer, and under the
// sanitizer tree in CI): every seed of fuzz/corpus/<harness>/ and every input that once made a
// harness fail, fuzz/regressions/<harness>/, loads or is refused with one InputError line; never
// a crash, a hang or another exception. The batch manifest parser reads a manifest listed many
// times once.

#include "io_test_util.hpp"
#include "readers.hpp"

#include "sdfkit/batch.hpp"
#include "sdfkit/io/asset.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace sdfkit {
namespace {

namespace fs = std::filesystem;

std::string bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Loads every file under fuzz/<set>/<harness>/ as the harness does; returns how many.
std::size_t load_all(const std::string& set, const std::string& harness, io::Format format) {
  const fs::path dir = fs::path(SDFKIT_SOURCE_DIR) / "fuzz" / set / harness;
  if (!fs::is_directory(dir)) return 0;
  io::LoadOptions options;
  options.max_triangles = 1u << 20;  // the harnesses' limits
  options.max_file_size = 1u << 24;
  test::ScratchDir scratch;  // an empty directory: a glTF's references resolve to nothing there
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string data = bytes_of(e.path());
    io::Format f = format;
    if (format == io::Format::Gltf && data.rfind("glTF", 0) == 0) f = io::Format::Glb;
    const std::string path = scratch.path("input." + std::string(io::format_name(f)));
    try {
      const io::Asset a = io::detail::load_from_memory(path, f, data, options);
      EXPECT_FALSE(a.mesh.triangles.empty()) << e.path();
      for (const Triangle& t : a.mesh.triangles)
        for (std::uint32_t v : t) EXPECT_LT(v, a.mesh.positions.size()) << e.path();
    } catch (const InputError& err) {
      const std::string msg = err.what();
      EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << e.path() << ": " << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << e.path() << ": " << msg;
    }
    ++n;
  }
  return n;
}

struct Harness {
  const char* name;
  io::Format format;
};
const Harness kHarnesses[] = {{"gltf", io::Format::Gltf},      {"obj", io::Format::Obj},
                              {"off", io::Format::Off},        {"ply_ascii", io::Format::Ply},
                              {"ply_binary", io::Format::Ply}};

TEST(FuzzCorpus, EverySeedLoadsOrIsRefusedCleanly) {
  for (const Harness& h : kHarnesses)
    EXPECT_GT(load_all("corpus", h.name, h.format), 0u) << "no seeds for " << h.name;
}

TEST(FuzzCorpus, EveryRegressionLoadsOrIsRefusedCleanly) {
  for (const Harness& h : kHarnesses) load_all("regressions", h.name, h.format);
}

TEST(FuzzCorpus, PlyElementsWithoutPropertiesCostNothing) {
  // Found by fuzz_ply_binary (a hang): an element with no properties holds no bytes, so the
  // header's size check let a count of 4.9e11 through, and the reader looped over empty rows.
  test::ScratchDir dir;
  for (const char* format : {"ascii", "binary_little_endian"}) {
    std::string ply = std::string("ply\nformat ") + format +
                      " 1.0\nelement nothing 488888888888\nelement vertex 3\nproperty float x\n"
                      "property float y\nproperty float z\nelement face 1\n"
                      "property list uchar int vertex_indices\nend_header\n";
    if (std::string(format) == "ascii") {
      ply += "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    } else {
      for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) test::put(ply, f);
      test::put<std::uint8_t>(ply, 3);
      for (std::int32_t i : {0, 1, 2}) test::put(ply, i);
    }
    const io::Asset a = io::load_asset(dir.write("empty-element.ply", ply));
    EXPECT_EQ(a.input_triangles.size(), 1u) << format;
  }
}

TEST(FuzzCorpus, ManifestsListedManyTimesAreReadOnce) {
  // m0.list lists m1.list 30 times, m1 lists m2 30 times, ... down to m7, which names a mesh:
  // expanded naively that is 30^7 manifest reads (a hang); each is read once.
  test::ScratchDir dir;
  for (int level = 0; level < 7; ++level) {
    std::string text = "# level " + std::to_string(level) + "\n";
    for (int i = 0; i < 30; ++i) text += "m" + std::to_string(level + 1) + ".list\n";
    dir.write("m" + std::to_string(level) + ".list", text);
  }
  dir.write("m7.list", "a.off\n");
  dir.write("a.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  const std::vector<std::string> inputs = expand_inputs({"@" + dir.path("m0.list")});
  ASSERT_EQ(inputs.size(), 1u);
  EXPECT_EQ(fs::path(inputs[0]).filename(), "a.off");
  // A manifest that lists itself adds nothing (it is not read again).
  dir.write("self.list", "self.list\na.off\n./self.list\n");
  EXPECT_EQ(expand_inputs({dir.path("self.list")}), inputs);
}

}  // namespace
}  // namespace sdfkit

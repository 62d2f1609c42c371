// libFuzzer harness: the PLY reader, seeded with binary files (see loader_fuzz.hpp). The
// ascii and binary harnesses run the same reader from different corpora.
#include "loader_fuzz.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return sdfkit::fuzz::load_one(data, size, sdfkit::io::Format::Ply, ".ply");
}

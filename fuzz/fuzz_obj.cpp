// libFuzzer harness: the OBJ reader (see loader_fuzz.hpp).
#include "loader_fuzz.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return sdfkit::fuzz::load_one(data, size, sdfkit::io::Format::Obj, ".obj");
}

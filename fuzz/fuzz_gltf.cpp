// libFuzzer harness: the glTF reader, .gltf text or .glb (an input starting with the glb magic
// "glTF" is read as a .glb), see loader_fuzz.hpp.
#include "loader_fuzz.hpp"

#include <cstring>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  return sdfkit::fuzz::load_one(data, size, glb ? sdfkit::io::Format::Glb : sdfkit::io::Format::Gltf,
                                glb ? ".glb" : ".gltf");
}

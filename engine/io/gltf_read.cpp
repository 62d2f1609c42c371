#include "readers.hpp"
namespace sdfkit::io::detail {
RawMesh read_gltf(const std::string& path, bool) { fail(path, "glTF not yet supported"); }
}

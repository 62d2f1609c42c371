#pragma once
// Internal to sdfkit_io: what the glTF reader keeps for write-back, and accessor helpers shared
// by the reader and the writer. Only sdfkit_io includes tiny_gltf.h (linked as the system's
// shared libtinygltf; TINYGLTF_IMPLEMENTATION is never defined here).

#include <tiny_gltf.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace sdfkit::io::detail {

// One drawn triangle primitive: mesh `mesh`'s primitive `primitive` placed by node `node`;
// its POSITION accessor's vertices are input vertices [first_vertex, first_vertex + count),
// its triangles input triangles [first_triangle, first_triangle + triangle_count); `world` is
// the node's world transform (column-major 4x4).
struct GltfPrimitiveInstance {
  int node = -1;
  int mesh = -1;
  int primitive = -1;
  std::uint32_t first_vertex = 0;
  std::uint32_t vertex_count = 0;
  std::uint32_t first_triangle = 0;
  std::uint32_t triangle_count = 0;
  std::array<double, 16> world{};
};

// Asset::source for glTF inputs.
struct GltfSource {
  tinygltf::Model model;
  std::vector<GltfPrimitiveInstance> instances;  // scene traversal order
};

// Loads an image's encoded bytes as they are (no decoding): textures survive write-back
// untouched and a missing or undecodable image never makes loading fail.
bool keep_image_bytes(tinygltf::Image* image, int image_index, std::string* err, std::string* warn,
                      int req_width, int req_height, const unsigned char* bytes, int size,
                      void* user_data);

}  // namespace sdfkit::io::detail

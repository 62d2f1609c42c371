// The fuzz build's tinygltf: the system header's implementation compiled here (with the
// fuzzer's coverage and the sanitizers) instead of linking the shared libtinygltf. Images are
// never decoded or encoded by sdfkit (it keeps their bytes, engine/io/gltf_model.hpp), so
// stb_image is left out and the default image callbacks, which TinyGLTF's constructor names,
// refuse.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#include <tiny_gltf.h>

namespace tinygltf {

bool LoadImageData(Image*, const int, std::string* err, std::string*, int, int,
                   const unsigned char*, int, void*) {
  if (err) *err += "image decoding is not built in\n";
  return false;
}

bool WriteImageData(const std::string*, const std::string*, const Image*, bool, std::string*,
                    void*) {
  return false;
}

}  // namespace tinygltf

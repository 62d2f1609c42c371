// write_png: the library's one PNG encoder (stb_image_write, Debian's libstb-dev), used by the
// figures (render) and the atlas picture (diffusion).
#include "sdfkit/core/error.hpp"
#include "sdfkit/io/asset.hpp"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

#include <ostream>

namespace sdfkit::io {

void write_png(const std::string& path, int width, int height, int channels,
               std::span<const std::uint8_t> pixels) {
  if (width <= 0 || height <= 0 || (channels != 3 && channels != 4) ||
      pixels.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) *
                           static_cast<std::size_t>(channels))
    throw Error(path + ": cannot write an empty or malformed image");
  std::string bytes;
  const auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), static_cast<std::size_t>(size));
  };
  if (!stbi_write_png_to_func(append, &bytes, width, height, channels, pixels.data(), width * channels))
    throw Error(path + ": PNG encoding failed");
  write_file_atomically(path, [&](std::ostream& out) {
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  });
}

}  // namespace sdfkit::io

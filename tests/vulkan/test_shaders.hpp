#pragma once
// The test shaders (tests/vulkan/shaders/), compiled at build time into the tests, not the library.

#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

namespace sdfkit::test::shaders {
struct EmbeddedShader {
  const char* name;
  const std::uint32_t* words;
  std::size_t size;
};
// Defined in the generated registry (cmake/SdfkitShaders.cmake).
std::span<const EmbeddedShader> embedded_shaders();
}  // namespace sdfkit::test::shaders

namespace sdfkit::test {

// The SPIR-V of a test shader by file name ("test_fill.comp").
inline std::span<const std::uint32_t> test_spirv(std::string_view name) {
  for (const auto& s : shaders::embedded_shaders())
    if (name == s.name) return {s.words, s.size};
  throw std::out_of_range("no test shader named '" + std::string(name) + "'");
}

}  // namespace sdfkit::test

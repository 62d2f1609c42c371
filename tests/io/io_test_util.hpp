#pragma once
// Helpers for the I/O tests: byte-exact file writing (the scratch directory is in tests/support).

#include "scratch.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/sdf.hpp"
#include "sdfkit/io/asset.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

namespace sdfkit::test {


inline std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Appends the bytes of `value` in little- (big = false) or big-endian order.
template <typename T>
void put(std::string& out, T value, bool big = false) {
  static_assert(std::is_trivially_copyable_v<T>);
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (big) {
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
  }
  out.append(bytes, sizeof(T));
}

// Runs `f`, expects an InputError whose message is one line starting with `path` and
// containing `needle`.
template <typename F>
void expect_input_error(F&& f, const std::string& path, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "no InputError for " << path << " (expected '" << needle << "')";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find(needle), std::string::npos)
        << "message: " << msg << "\nexpected: " << needle;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type for " << path << ": " << e.what();
  }
}

// A cube of quads: 8 vertices, 12 triangles after fan triangulation.
inline const std::string kCubeOff =
    "OFF\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
    "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n4 0 4 7 3\n";

// A field with distinct values per welded vertex (or face), increasing, and not representable
// in a few digits, so text round trips must keep every significant digit.
inline SdfField ramp_field(const io::Asset& a, SdfDomain domain) {
  SdfField f;
  f.domain = domain;
  const std::size_t n = domain == SdfDomain::Vertex ? a.mesh.vertex_count() : a.mesh.face_count();
  for (std::size_t i = 0; i < n; ++i) f.values.push_back(0.1f + 0.37f * static_cast<float>(i) / 3.0f);
  f.kept_rays.assign(n, 30);
  f.filled.assign(n, 0);
  return f;
}

}  // namespace sdfkit::test

#pragma once
// Pinned values: a few fixed meshes' SDF as the backends computed it when the test was written,
// so that refactoring the device code (render graph, shared definition) is held to the values it
// had before. Tolerances are far below any real change (a lost or extra sample moves a value by
// percents) and leave room for the rounding of another CPU's LLVM code generation.
// SDFKIT_PRINT_PINNED=1 prints the current values in the initializer syntax used below.

#include "sdfkit/core/mesh.hpp"
#include "sdfkit/core/sdf.hpp"
#include "sdfkit/core/shapes.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace sdfkit::test {

// A torus with every seventh triangle removed: boundary edges, so front layers / front-face
// hits matter and the two false-hit rules give different values.
inline Mesh open_torus() {
  Mesh m = shapes::torus(3.0f, 1.0f, 40, 20);
  std::vector<Triangle> kept;
  for (std::size_t f = 0; f < m.triangles.size(); ++f)
    if (f % 7 != 3) kept.push_back(m.triangles[f]);
  m.triangles = std::move(kept);
  return m;
}

inline constexpr std::array<std::size_t, 6> kPinnedPoints = {0, 97, 233, 401, 555, 760};

struct Pinned {
  double sum = 0.0;                      // sum of the values of the points with a value
  std::size_t with_value = 0;            // points with at least one kept ray
  std::array<float, 6> values{};         // at kPinnedPoints
};

inline Pinned pin_of(const RawSdf& r) {
  Pinned p;
  for (std::size_t i = 0; i < r.values.size(); ++i)
    if (r.kept_rays[i] > 0) {
      p.sum += r.values[i];
      ++p.with_value;
    }
  for (std::size_t k = 0; k < kPinnedPoints.size(); ++k) p.values[k] = r.values.at(kPinnedPoints[k]);
  return p;
}

inline void expect_pinned(const RawSdf& got, const Pinned& want, const std::string& what) {
  const Pinned p = pin_of(got);
  if (const char* e = std::getenv("SDFKIT_PRINT_PINNED"); e && std::string(e) == "1") {
    std::printf("  // %s\n  {%.9g, %zu, {", what.c_str(), p.sum, p.with_value);
    for (std::size_t k = 0; k < p.values.size(); ++k) std::printf("%s%.9gf", k ? ", " : "", p.values[k]);
    std::printf("}},\n");
  }
  EXPECT_EQ(p.with_value, want.with_value) << what;
  EXPECT_NEAR(p.sum, want.sum, 1e-5 * std::fabs(want.sum)) << what;
  for (std::size_t k = 0; k < p.values.size(); ++k)
    EXPECT_NEAR(p.values[k], want.values[k], 1e-4f * std::fabs(want.values[k]))
        << what << ", point " << kPinnedPoints[k];
}

}  // namespace sdfkit::test

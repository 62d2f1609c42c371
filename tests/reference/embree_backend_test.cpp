// The Embree reference backend: interface behaviour, determinism, open and degenerate meshes.
#include "analytic.hpp"
#include "compare.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/reference/embree_backend.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace sdfkit;
using reference::EmbreeBackend;

TEST(EmbreeBackend, NamesItself) {
  EmbreeBackend b;
  EXPECT_EQ(b.name(), "embree");
  EXPECT_NE(b.device_name().find("Embree 3."), std::string::npos) << b.device_name();
}

#pragma once
// One OpenCL backend shared by all tests of the binary (the program is compiled once).
// Without an OpenCL device the tests fail, unless SDFKIT_ALLOW_NO_DEVICE=1 makes them skip.

#include "device_policy.hpp"

#include "sdfkit/opencl/opencl_backend.hpp"

#include <gtest/gtest.h>

namespace sdfkit::test {

// The tracer variants the tests cover: the BVH with bundles of 16 points per ray (the default
// on CPU devices), the BVH with one ray per work item (the default on GPUs), the octree.
enum class Tracer { BvhBundles, BvhSingle, Octree };
const char* tracer_name(Tracer t);

// The shared backend of that variant, or nullptr when no device exists (use SDFKIT_REQUIRE_CL
// / SDFKIT_REQUIRE_CL_ACCEL, which fail or skip the test then).
cl::OpenClBackend* opencl_backend(Tracer tracer = Tracer::BvhBundles);

}  // namespace sdfkit::test

// Binds `var` to the shared backend; fails (or skips, with SDFKIT_ALLOW_NO_DEVICE=1) the test
// when there is no OpenCL device.
#define SDFKIT_REQUIRE_CL(var) SDFKIT_REQUIRE_CL_ACCEL(var, ::sdfkit::test::Tracer::BvhBundles)
#define SDFKIT_REQUIRE_CL_ACCEL(var, tracer)                               \
  cl::OpenClBackend* var##_ptr = ::sdfkit::test::opencl_backend(tracer);   \
  if (var##_ptr == nullptr) {                                             \
    if (::sdfkit::test::allow_no_device())                              \
      GTEST_SKIP() << "no OpenCL device (SDFKIT_ALLOW_NO_DEVICE=1)";      \
    FAIL() << "no OpenCL device; install pocl-opencl-icd or set SDFKIT_ALLOW_NO_DEVICE=1"; \
  }                                                                       \
  cl::OpenClBackend& var = *var##_ptr

namespace sdfkit::test {
}

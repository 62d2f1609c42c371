#pragma once
// Shared by the depth-peeling tests: a backend with validation on.

#include "vk_test_util.hpp"

#include "sdfkit/vulkan/depth_peel.hpp"

#include <memory>

namespace sdfkit::test {

// A validated depth-peeling backend, or nullptr when no device exists and
// SDFKIT_ALLOW_NO_DEVICE=1 (a missing device fails otherwise).
inline std::unique_ptr<vk::DepthPeelBackend> make_test_backend(const vk::DepthPeelConfig& config) {
  return make_validated<vk::DepthPeelBackend>(config);
}

}  // namespace sdfkit::test

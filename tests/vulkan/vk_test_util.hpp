#pragma once
// Shared by the Vulkan device tests: a context with validation on, the SDFKIT_ALLOW_NO_DEVICE
// escape hatch (a missing device fails otherwise), and the zero-validation-message check.

#include "device_policy.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/vulkan/context.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <string>

namespace sdfkit::test {

// A T made from `config` with validation on, or nullptr when no device exists and
// SDFKIT_ALLOW_NO_DEVICE=1 (a missing device fails otherwise).
template <typename T, typename Config>
std::unique_ptr<T> make_validated(Config config) {
  config.validation = true;
  try {
    return std::make_unique<T>(config);
  } catch (const DeviceError&) {
    if (allow_no_device()) return nullptr;
    throw;
  }
}

// A validated context, or nullptr when no device exists and SDFKIT_ALLOW_NO_DEVICE=1.
inline std::unique_ptr<vk::Context> make_test_context(vk::ContextConfig config = {}) {
  return make_validated<vk::Context>(config);
}

// Joins the validation messages for a failure message.
inline std::string joined(const std::vector<std::string>& messages) {
  std::string s;
  for (const auto& m : messages) s += m + "\n";
  return s;
}

#define SDFKIT_EXPECT_NO_VALIDATION_MESSAGES(ctx) \
  EXPECT_EQ((ctx).validation_message_count(), 0u) << ::sdfkit::test::joined((ctx).validation_messages())

// A fixture with a validated context `ctx_` (the test is skipped when no device exists and
// SDFKIT_ALLOW_NO_DEVICE=1) that fails a test which left validation messages behind.
class DeviceTest : public ::testing::Test {
protected:
  void SetUp() override {
    ctx_ = make_test_context();
    if (!ctx_) GTEST_SKIP() << "no Vulkan device";
  }
  void TearDown() override {
    if (ctx_) {
      SDFKIT_EXPECT_NO_VALIDATION_MESSAGES(*ctx_);
    }
  }
  std::unique_ptr<vk::Context> ctx_;
};

}  // namespace sdfkit::test

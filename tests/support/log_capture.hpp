#pragma once
// Captures the engine's log warnings while alive (restores the default sink on scope exit, also
// when an assertion fails in between).

#include "sdfkit/core/log.hpp"

#include <mutex>
#include <string>
#include <string_view>
#include <vector>

namespace sdfkit::test {

class WarningCapture {
public:
  WarningCapture() {
    set_log_sink([this](LogLevel level, std::string_view m) {
      if (level == LogLevel::Warning) {
        std::lock_guard lock(mutex_);
        messages_.emplace_back(m);
      }
    });
  }
  ~WarningCapture() { set_log_sink(nullptr); }
  WarningCapture(const WarningCapture&) = delete;
  WarningCapture& operator=(const WarningCapture&) = delete;
  std::vector<std::string> messages() {
    std::lock_guard lock(mutex_);
    return messages_;
  }

private:
  std::mutex mutex_;
  std::vector<std::string> messages_;
};

}  // namespace sdfkit::test

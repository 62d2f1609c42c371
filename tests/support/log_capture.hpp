#pragma once
// Captures the engine's log messages of one level while alive, lowering the log level to it if
// needed; restores the default sink and level on scope exit, also when an assertion fails.

#include "sdfkit/core/log.hpp"

#include <mutex>
#include <string>
#include <string_view>
#include <vector>

namespace sdfkit::test {

class LogCapture {
public:
  explicit LogCapture(LogLevel level = LogLevel::Warning) : previous_(log_level()) {
    if (level < previous_) set_log_level(level);
    set_log_sink([this, level](LogLevel l, std::string_view m) {
      if (l == level) {
        std::lock_guard lock(mutex_);
        messages_.emplace_back(m);
      }
    });
  }
  ~LogCapture() {
    set_log_sink(nullptr);
    set_log_level(previous_);
  }
  LogCapture(const LogCapture&) = delete;
  LogCapture& operator=(const LogCapture&) = delete;
  std::vector<std::string> messages() {
    std::lock_guard lock(mutex_);
    return messages_;
  }

private:
  LogLevel previous_;
  std::mutex mutex_;
  std::vector<std::string> messages_;
};

}  // namespace sdfkit::test

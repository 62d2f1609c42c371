#include "sdfkit/core/log.hpp"

#include <atomic>
#include <cstdio>
#include <mutex>

namespace sdfkit {
namespace {

std::mutex g_mutex;
LogSink g_sink;
std::atomic<LogLevel> g_level{LogLevel::Warning};

const char* prefix(LogLevel level) {
  switch (level) {
    case LogLevel::Debug: return "debug";
    case LogLevel::Info: return "info";
    case LogLevel::Warning: return "warning";
    case LogLevel::Error: return "error";
  }
  return "log";
}

}  // namespace

void set_log_sink(LogSink sink) {
  std::lock_guard lock(g_mutex);
  g_sink = std::move(sink);
}

void set_log_level(LogLevel level) { g_level.store(level); }
LogLevel log_level() { return g_level.load(); }

void log(LogLevel level, std::string_view message) {
  if (level < g_level.load()) return;
  std::lock_guard lock(g_mutex);
  if (g_sink) {
    g_sink(level, message);
    return;
  }
  std::fprintf(stderr, "sdfkit: %s: %.*s\n", prefix(level), static_cast<int>(message.size()),
               message.data());
}

}  // namespace sdfkit

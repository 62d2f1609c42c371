#pragma once
// A tiny logging sink. The engine reports warnings and progress through it; an embedding
// application replaces the sink to route messages into its own logger.

#include <functional>
#include <string>
#include <string_view>

namespace sdfkit {

enum class LogLevel { Debug, Info, Warning, Error };

using LogSink = std::function<void(LogLevel, std::string_view)>;

// Replaces the process-wide sink (thread-safe). The default prints warnings and errors to stderr.
void set_log_sink(LogSink sink);
// Messages below this level are dropped before they reach the sink. Default: Warning.
void set_log_level(LogLevel level);
LogLevel log_level();

void log(LogLevel level, std::string_view message);
inline void log_warning(std::string_view m) { log(LogLevel::Warning, m); }
inline void log_info(std::string_view m) { log(LogLevel::Info, m); }
inline void log_debug(std::string_view m) { log(LogLevel::Debug, m); }

}  // namespace sdfkit

#include "core/log.h"

#include <memory>
#include <mutex>
#include <ostream>

namespace ort {

const char* to_string(LogLevel level) {
  switch (level) {
    case LogLevel::kInfo: return "info";
    case LogLevel::kWarning: return "warning";
    case LogLevel::kError: return "error";
  }
  return "?";
}

Log::Log(std::ostream& out) : Log(log_to(out)) {}

void Log::lines(LogLevel level, std::string_view text) const {
  while (!text.empty()) {
    const size_t end = text.find('\n');
    const std::string_view line = text.substr(0, end);
    if (!line.empty()) (*this)(level, line);
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
}

Log log_to(std::ostream& out, std::string program) {
  auto mutex = std::make_shared<std::mutex>();
  if (!program.empty()) program += ": ";
  return Log([&out, mutex, program = std::move(program)](LogLevel level, std::string_view message) {
    std::string line = program;
    if (level != LogLevel::kInfo) (line += to_string(level)) += ": ";
    line.append(message);
    line += '\n';
    std::lock_guard lock(*mutex);
    out << line << std::flush;
  });
}

Log log_into(std::string& text) {
  return Log([&text](LogLevel, std::string_view message) {
    text += message;
    text += '\n';
  });
}

}  // namespace ort

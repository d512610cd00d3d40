// How library code says things: a Log wraps a callable(level, message) that the caller passes
// in (the daemon routes it to its log stream, the CLI to stderr, tests into a string). No
// global logger: a component that has something to say takes a Log. A default Log discards.
#pragma once

#include <functional>
#include <iosfwd>
#include <string>
#include <string_view>
#include <utility>

namespace ort {

enum class LogLevel { kInfo, kWarning, kError };

const char* to_string(LogLevel level);

class Log {
 public:
  using Sink = std::function<void(LogLevel, std::string_view)>;

  Log() = default;
  explicit Log(Sink sink) : sink_(std::move(sink)) {}

  // One message: one line of text without the trailing newline.
  void operator()(LogLevel level, std::string_view message) const {
    if (sink_) sink_(level, message);
  }
  void info(std::string_view message) const { (*this)(LogLevel::kInfo, message); }
  void warning(std::string_view message) const { (*this)(LogLevel::kWarning, message); }
  void error(std::string_view message) const { (*this)(LogLevel::kError, message); }
  // Each non-empty line of `text` as one message (for notes collected as text).
  void lines(LogLevel level, std::string_view text) const;

 private:
  Sink sink_;
};

// A Log that writes "message\n" to `out` (which must outlive it).
Log log_to(std::ostream& out);
// A Log that appends "message\n" to `text` (which must outlive it): tests, collected notes.
Log log_into(std::string& text);

}  // namespace ort

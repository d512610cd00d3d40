// How library code says things: a Log wraps a callable(level, message) that the caller passes
// in (the daemon routes it to its log stream, the CLI to stderr, tests into a string). No
// global logger: a component that has something to say takes a Log. A default Log discards.
//
// A Log made on a stream (log_to, or the converting constructor) writes whole lines under a
// mutex that its copies share, so the threads of one program that share a Log never interleave
// their lines: make one where the program starts and hand copies down.
#pragma once

#include <functional>
#include <iosfwd>
#include <sstream>
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
  // log_to(out): a thread-safe sink on `out` (which must outlive the Log and its copies).
  Log(std::ostream& out);  // NOLINT(google-explicit-constructor): any stream where a Log is asked

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

// A Log that writes each message as one line to `out` (which must outlive it), under a mutex
// its copies share: "PROGRAM: message", with "warning: " or "error: " after the program's
// name for those levels ("PROGRAM: " is left out when `program` is empty).
Log log_to(std::ostream& out, std::string program = "");
// A Log that appends "message\n" to `text` (which must outlive it): tests, collected notes.
Log log_into(std::string& text);

// The text of `parts` as a stream writes them: log.warning(text("took ", ms, " ms")).
template <class... Parts>
std::string text(const Parts&... parts) {
  std::ostringstream out;
  (out << ... << parts);
  return std::move(out).str();
}

}  // namespace ort

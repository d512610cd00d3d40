#include "cli/octomap_chatter.h"

#include <unistd.h>

#include <algorithm>
#include <initializer_list>
#include <mutex>
#include <ostream>
#include <streambuf>
#include <string>

namespace ort::cli {

namespace {

// "Writing 1598 nodes to output stream... done." (OccupancyOcTreeBase::writeBinaryData, then
// writeBinaryConst), "Reading 10201 points from binary file...done." (Pointcloud::readBinary)
// and their kin: "Reading|Writing|reading|writing N nodes|points|edges from|to binary
// file|output stream...", optionally followed by "done." or " done.". A program built with
// NDEBUG instantiates writeBinaryData silently itself, and only the library's " done." is left.
bool is_stdio_progress(std::string_view line) {
  if (line == " done.") return true;
  auto take = [&](std::string_view p) {
    if (line.substr(0, p.size()) != p) return false;
    line.remove_prefix(p.size());
    return true;
  };
  auto take_any = [&](std::initializer_list<std::string_view> ps) {
    for (std::string_view p : ps)
      if (take(p)) return true;
    return false;
  };
  if (!take_any({"Reading ", "Writing ", "reading ", "writing "})) return false;
  const size_t digits = line.find_first_not_of("0123456789");
  if (digits == 0 || digits == std::string_view::npos) return false;
  line.remove_prefix(digits);
  if (!take_any({" nodes ", " points ", " edges "}) || !take_any({"from ", "to "})) return false;
  if (!take_any({"binary file...", "output stream..."})) return false;
  return line.empty() || line == "done." || line == " done.";
}

// Whether `partial` (a line without its end yet) may still become one of them.
bool may_become_stdio_progress(std::string_view partial) {
  for (std::string_view p : {"Reading ", "Writing ", "reading ", "writing ", " done."}) {
    const size_t n = std::min(p.size(), partial.size());
    if (partial.substr(0, n) == p.substr(0, n)) return true;
  }
  return false;
}

}  // namespace

bool is_octomap_chatter(std::string_view line) {
  auto starts = [&](std::string_view p) { return line.substr(0, p.size()) == p; };
  if (starts("Reading binary octree type ") || starts("Reading octree type ")) return true;
  if (is_stdio_progress(line)) return true;
  // "Done (17 nodes)"
  if (!starts("Done (") || line.size() < 13 || line.substr(line.size() - 7) != " nodes)") return false;
  const std::string_view n = line.substr(6, line.size() - 13);
  return !n.empty() && n.find_first_not_of("0123456789") == std::string_view::npos;
}

// Collects a line (to '\n', or '\r' for a progress bar), then hands it to the stream's own
// buffer unless it is OctoMap's. A flush (std::cerr flushes after every insertion) passes only
// whole lines: OctoMap writes its lines in pieces.
class OctomapChatterFilter::Buffer : public std::streambuf {
 public:
  explicit Buffer(std::streambuf* out) : out_(out) {}
  std::streambuf* out() const { return out_; }
  ~Buffer() override {
    if (!line_.empty()) flush_line();
    out_->pubsync();
  }

 protected:
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    const char ch = traits_type::to_char_type(c);
    std::lock_guard lock(mutex_);
    line_ += ch;
    if (ch == '\n' || ch == '\r') flush_line();
    return c;
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    for (std::streamsize i = 0; i < n; ++i) overflow(traits_type::to_int_type(s[i]));
    return n;
  }
  int sync() override { return out_->pubsync(); }

 private:
  void flush_line() {  // under mutex_
    std::string_view whole(line_);
    if (!whole.empty() && (whole.back() == '\n' || whole.back() == '\r')) whole.remove_suffix(1);
    if (!is_octomap_chatter(whole)) out_->sputn(line_.data(), static_cast<std::streamsize>(line_.size()));
    line_.clear();
  }

  std::streambuf* out_;
  std::mutex mutex_;
  std::string line_;
};

// Bytes from the C stream, a line at a time (to '\n' or '\r'): OctoMap's lines are dropped,
// others written to `fd`; a line that cannot become one of OctoMap's is written as it comes.
class OctomapStdioFilter::Lines {
 public:
  explicit Lines(int fd) : fd_(fd) {}
  void write(const char* s, size_t n) {
    for (size_t i = 0; i < n; ++i) {
      line_ += s[i];
      if (s[i] == '\n' || s[i] == '\r') {
        std::string_view whole(line_);
        whole.remove_suffix(1);
        if (passing_ || !is_octomap_chatter(whole)) out(line_);
        line_.clear();
        passing_ = false;
      } else if (passing_ || !may_become_stdio_progress(line_)) {
        passing_ = true;
        out(line_);
        line_.clear();
      }
    }
  }
  void finish() {
    if (!line_.empty() && !is_octomap_chatter(line_)) out(line_);
    line_.clear();
  }

 private:
  void out(const std::string& bytes) {
    for (size_t done = 0; done < bytes.size();) {
      const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
      if (n <= 0) return;  // stderr gone: nothing to tell
      done += static_cast<size_t>(n);
    }
  }
  int fd_;
  std::string line_;
  bool passing_ = false;  // the current line is not OctoMap's: its bytes pass as they come
};

OctomapStdioFilter::OctomapStdioFilter() : original_(stderr), lines_(std::make_unique<Lines>(::fileno(stderr))) {
  cookie_io_functions_t io{};
  io.write = [](void* cookie, const char* s, size_t n) -> ssize_t {
    static_cast<Lines*>(cookie)->write(s, n);
    return static_cast<ssize_t>(n);
  };
  std::fflush(original_);
  filtered_ = ::fopencookie(lines_.get(), "w", io);
  if (!filtered_) return;                       // no filter: OctoMap's lines pass, nothing else changes
  std::setvbuf(filtered_, nullptr, _IONBF, 0);  // as stderr: every write reaches the filter at once
  stderr = filtered_;
}

OctomapStdioFilter::~OctomapStdioFilter() {
  if (!filtered_) return;
  stderr = original_;
  std::fclose(filtered_);
  lines_->finish();
}

OctomapChatterFilter::OctomapChatterFilter(std::ostream& stream)
    : stream_(stream), buffer_(std::make_unique<Buffer>(stream.rdbuf())) {
  stream_.rdbuf(buffer_.get());
}

OctomapChatterFilter::~OctomapChatterFilter() {
  buffer_->pubsync();
  stream_.rdbuf(buffer_->out());
}

}  // namespace ort::cli

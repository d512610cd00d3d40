#include "cli/octomap_chatter.h"

#include <mutex>
#include <ostream>
#include <streambuf>
#include <string>

namespace ort::cli {

bool is_octomap_chatter(std::string_view line) {
  auto starts = [&](std::string_view p) { return line.substr(0, p.size()) == p; };
  if (starts("Reading binary octree type ") || starts("Reading octree type ")) return true;
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

OctomapChatterFilter::OctomapChatterFilter(std::ostream& stream)
    : stream_(stream), buffer_(std::make_unique<Buffer>(stream.rdbuf())) {
  stream_.rdbuf(buffer_.get());
}

OctomapChatterFilter::~OctomapChatterFilter() {
  buffer_->pubsync();
  stream_.rdbuf(buffer_->out());
}

}  // namespace ort::cli

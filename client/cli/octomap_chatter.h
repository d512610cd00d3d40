// OctoMap 1.9.7 as Debian builds it (without NDEBUG) writes progress lines on every tree it
// reads or writes: to std::cerr ("Reading binary octree type OcTree", "Reading octree type
// OcTree", "Done (N nodes)") and through C stdio's stderr ("Writing N nodes to output
// stream... done." from writeBinary, or its " done." alone, "Reading N points from binary
// file...done." from a scan graph's clouds): lines a user of octomap-rt reads as messages of its own, on every command
// that fetches, renders, compares, builds or merges a map. The CLI's std::cerr and its C
// stderr pass through filters that drop exactly those lines and pass every other one on whole.
#pragma once

#include <cstdio>
#include <iosfwd>
#include <memory>
#include <string_view>

namespace ort::cli {

// Whether `line` (without its newline) is one of OctoMap's progress lines.
bool is_octomap_chatter(std::string_view line);

// While it lives, `stream` (std::cerr in the CLI's main) writes through a filter that drops
// OctoMap's progress lines; the stream's own buffer is restored when it goes. Writes from
// several threads are serialised line by line.
class OctomapChatterFilter {
 public:
  explicit OctomapChatterFilter(std::ostream& stream);
  ~OctomapChatterFilter();
  OctomapChatterFilter(const OctomapChatterFilter&) = delete;
  OctomapChatterFilter& operator=(const OctomapChatterFilter&) = delete;

 private:
  class Buffer;
  std::ostream& stream_;
  std::unique_ptr<Buffer> buffer_;
};

// While it lives, C stdio's `stderr` (what OctoMap's fprintf(stderr, ...) writes to) is a
// stream that drops OctoMap's progress lines and writes every other byte to the file
// descriptor stderr had; the original is restored when it goes. In the GNU C library stdin,
// stdout and stderr are variables a program may set (its manual, "Standard Streams"). A line
// that cannot be one of OctoMap's passes at once, so nothing waits for a newline that never comes.
class OctomapStdioFilter {
 public:
  OctomapStdioFilter();
  ~OctomapStdioFilter();
  OctomapStdioFilter(const OctomapStdioFilter&) = delete;
  OctomapStdioFilter& operator=(const OctomapStdioFilter&) = delete;

  class Lines;  // the line filter behind the stream

 private:
  std::FILE* original_;
  std::FILE* filtered_ = nullptr;
  std::unique_ptr<Lines> lines_;
};

}  // namespace ort::cli

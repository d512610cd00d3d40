// OctoMap 1.9.7 as Debian builds it (without NDEBUG) writes progress lines to std::cerr on
// every tree it reads ("Reading binary octree type OcTree", "Reading octree type OcTree",
// "Done (N nodes)"): lines a user of octomap-rt reads as messages of its own, on every
// command that fetches, renders, compares or loads a map. The CLI's std::cerr passes through
// this filter, which drops exactly those lines and passes every other one on whole.
#pragma once

#include <iosfwd>
#include <memory>
#include <string_view>

namespace ort::cli {

// Whether `line` (without its newline) is one of OctoMap's read progress lines.
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

}  // namespace ort::cli

// Typed refusals. A back end that cannot run here (no Vulkan device, a device without the
// extensions it needs, a traversal mode it does not implement) throws Unsupported; the
// automatic choice moves on only after such a refusal. Anything else (out of device memory,
// a failed submission, a bug) is a std::runtime_error or std::logic_error and surfaces.
#pragma once

#include <stdexcept>
#include <string>

namespace ort {

class Unsupported : public std::runtime_error {
 public:
  explicit Unsupported(const std::string& why) : std::runtime_error(why) {}
};

}  // namespace ort

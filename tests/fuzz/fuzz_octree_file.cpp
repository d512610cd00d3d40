// libFuzzer target: an OctoMap tree file (.ot or .bt) as the server's --map loading and the
// real-map scenes read it. check_octree_file must never crash (no recursion, no reads past
// the end); a file it accepts must be read by OctoMap's own reader to its last byte with
// exactly the checked number of nodes.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string_view>

#include "core/file_checks/octree_file_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  for (bool inner_is_max : {false, true}) {
    const ort::OctreeFileCheck check = ort::check_octree_file(bytes, inner_is_max);
    if (!check.ok) continue;
    try {
      const auto tree = ort::read_octree_file_bytes(bytes, "fuzz", inner_is_max);
      if (tree->size() != check.nodes) std::abort();
    } catch (const std::runtime_error&) {
      std::abort();  // checked, and still OctoMap's reader did not consume it whole
    }
  }
  return 0;
}

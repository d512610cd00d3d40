// libFuzzer target: a .graph file as `octomap-rt build`/`replay` read it (parse_scan_graph:
// the layout check, then OctoMap's own ScanNode reader). A file the check accepts must be
// read whole by OctoMap with the same scan and point counts; any other file must end in a
// std::runtime_error, never an assertion or a huge allocation.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string_view>

#include "core/file_checks/scan_graph_check.h"
#include "scene/scan_set.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const ort::ScanGraphCheck check = ort::check_scan_graph(bytes);
  try {
    const ort::ScanSet set = ort::parse_scan_graph(bytes, "fuzz.graph");
    if (!check.ok || set.scans.size() != check.scans || set.total_points() != check.points) std::abort();
  } catch (const std::runtime_error&) {
    if (check.ok && check.scans > 0) std::abort();  // checked, and still OctoMap could not read it
  }
  return 0;
}

// Names of the back ends and traversal modes, as the command line and the status spell them.
#include "core/backend_kind.h"

namespace ort {

const char* to_string(Traversal t) { return t == Traversal::kOctomap ? "octomap" : "exact"; }

const char* to_string(BackendKind b) {
  switch (b) {
    case BackendKind::kAuto: return "auto";
    case BackendKind::kCpu: return "cpu";
    case BackendKind::kCpuGrid: return "cpu-grid";
    case BackendKind::kVulkan: return "vulkan";
    case BackendKind::kRt: return "rt";
  }
  return "?";
}

bool parse_traversal(const std::string& s, Traversal& out) {
  if (s == "octomap") out = Traversal::kOctomap;
  else if (s == "exact") out = Traversal::kExact;
  else return false;
  return true;
}

bool parse_backend(const std::string& s, BackendKind& out) {
  if (s == "auto") out = BackendKind::kAuto;
  else if (s == "cpu") out = BackendKind::kCpu;
  else if (s == "cpu-grid") out = BackendKind::kCpuGrid;
  else if (s == "vulkan") out = BackendKind::kVulkan;
  else if (s == "rt") out = BackendKind::kRt;
  else return false;
  return true;
}

}  // namespace ort

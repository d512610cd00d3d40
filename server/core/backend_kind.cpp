// Names of the back ends and traversal modes, as the command line and the status spell them.
#include "core/backend_kind.h"

#include <array>
#include <utility>

namespace ort {
namespace {

// The one list of back-end names: to_string, parse_backend and --backend's choices use it.
constexpr std::array<std::pair<BackendKind, const char*>, 5> kBackendNames{{
    {BackendKind::kAuto, "auto"},
    {BackendKind::kCpu, "cpu"},
    {BackendKind::kCpuGrid, "cpu-grid"},
    {BackendKind::kVulkan, "vulkan"},
    {BackendKind::kRt, "rt"},
}};

}  // namespace

const char* to_string(Traversal t) { return t == Traversal::kOctomap ? "octomap" : "exact"; }

const char* to_string(BackendKind b) {
  for (const auto& [kind, name] : kBackendNames) {
    if (kind == b) return name;
  }
  return "?";
}

bool parse_traversal(const std::string& s, Traversal& out) {
  if (s == "octomap")
    out = Traversal::kOctomap;
  else if (s == "exact")
    out = Traversal::kExact;
  else
    return false;
  return true;
}

bool parse_backend(const std::string& s, BackendKind& out) {
  for (const auto& [kind, name] : kBackendNames) {
    if (s == name) {
      out = kind;
      return true;
    }
  }
  return false;
}

std::vector<std::string> backend_names() {
  std::vector<std::string> names;
  for (const auto& entry : kBackendNames) names.emplace_back(entry.second);
  return names;
}

}  // namespace ort

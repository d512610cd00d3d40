// The back ends a parameterized test runs on (each skips itself where it has no device), and
// their names as gtest takes them: INSTANTIATE_TEST_SUITE_P(EveryBackEnd, Suite,
// kEveryBackend, backend_param_name).
#pragma once

#include <string>

#include <gtest/gtest.h>

#include "core/backend_kind.h"
#include "core/traversal.h"

namespace ort::test {

inline const auto kEveryBackend =
    ::testing::Values(BackendKind::kCpu, BackendKind::kCpuGrid, BackendKind::kVulkan, BackendKind::kRt);

// "cpu-grid" -> "cpu_grid": gtest names are identifiers.
inline std::string backend_param_name(const ::testing::TestParamInfo<BackendKind>& info) {
  std::string n = to_string(info.param);
  for (char& c : n)
    if (c == '-') c = '_';
  return n;
}

// The traversal a back end's map is compared under: the rt back end walks the exact traversal
// only (its map is compared with the cpu back end's exact walk), the others OctoMap's own
// (compared with OctoMap itself).
inline Traversal reference_traversal(BackendKind kind) {
  return kind == BackendKind::kRt ? Traversal::kExact : Traversal::kOctomap;
}

}  // namespace ort::test

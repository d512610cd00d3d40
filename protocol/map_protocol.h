// The map protocol's own pieces beside the shared ones (channels.h, limits.h, ids.h,
// inbound_checks.h): the blob hash (docs/PROTOCOL.md).
#pragma once

#include <cstddef>
#include <cstdint>

namespace ort::protocol {

// FNV-1a, 64 bit: cheap, no dependency, good enough to catch a wrongly assembled blob
// (not an integrity check against an attacker).
inline int64_t blob_hash(const void* data, size_t size) {
  uint64_t h = 1469598103934665603ull;
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return static_cast<int64_t>(h);
}

}  // namespace ort::protocol

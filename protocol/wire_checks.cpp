#include "protocol/wire_checks.h"

#include <cstdint>
#include <exception>
#include <string>

#include "protocol/map_protocol.h"
#include "protocol/wire_layout.h"

namespace ort::protocol {
namespace {

// Walks the bytes by `layout` (wire_layout.h), then decodes inside try/catch.
template <class T>
std::string checked_decode(const void* data, size_t size, std::initializer_list<WireSegment> layout, T& out) {
  if (size > kMaxMessageBytes + 4096) return "too large";
  // The short name (no bound): these answers go into logs and the client's error messages.
  if (const WireCheck c = check_wire(static_cast<const uint8_t*>(data), size, T::getHash(), layout); !c.ok())
    return wire_fault_name(c.fault);
  try {
    const int n = out.decode(data, 0, static_cast<int>(size));
    if (n < 0) return "truncated";
    if (static_cast<size_t>(n) != size) return "trailing bytes";
  } catch (const std::exception&) {
    return "malformed";
  }
  return "";
}

constexpr int64_t kAnyString = static_cast<int64_t>(kMaxMessageBytes);

}  // namespace

// Each layout: the fixed fields before the count (fingerprint excluded), the count, the
// array, then the strings (the .lcm files' order).
std::string check_chunk(const void* data, size_t size, octomap_rt::map_chunk_t& out) {
  return checked_decode(data, size,
                        {wire_fixed(kChunkDataSizeOffset - 8), wire_count(kMaxMessageBytes), wire_array(1),
                         wire_string(kAnyString), wire_string(kAnyString), wire_string(kAnyString)},
                        out);
}
std::string check_delta(const void* data, size_t size, octomap_rt::map_delta_t& out) {
  return checked_decode(
      data, size,
      {wire_fixed(kDeltaDataSizeOffset - 8), wire_count(kMaxMessageBytes), wire_array(1), wire_string(kAnyString)},
      out);
}
std::string check_info(const void* data, size_t size, octomap_rt::map_info_t& out) {
  // Each producer: an int64 seq (all seqs first), then one id string each.
  return checked_decode(data, size,
                        {wire_fixed(kInfoNumProducersOffset - 8), wire_count(4096), wire_array(8),
                         wire_strings(1, kAnyString), wire_string(kAnyString), wire_string(kAnyString)},
                        out);
}
std::string check_request(const void* data, size_t size, octomap_rt::map_request_t& out) {
  return checked_decode(data, size,
                        {wire_fixed(kRequestNumIndicesOffset - 8), wire_count(kMaxRequestedChunks), wire_array(4),
                         wire_string(kAnyString), wire_string(kAnyString)},
                        out);
}

}  // namespace ort::protocol

#include "protocol/wire_checks.h"

#include <cstdint>
#include <exception>
#include <string>

#include "protocol/map_protocol.h"

namespace ort::protocol {
namespace {

int64_t read_be(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  if (bytes == 4) return static_cast<int32_t>(static_cast<uint32_t>(v));
  return static_cast<int64_t>(v);
}

// Where a message's one counted array sits and what follows it. LCM 1.3.1's generated
// decode() trusts every length: a negative or oversized string length makes it read past
// the buffer (or overflow `len - 1`), so the whole tail is walked here first.
struct Layout {
  size_t count_offset;      // of the int32 count, fingerprint included
  size_t elem_size;         // fixed bytes per counted element
  int strings_per_elem;     // strings per counted element, after the fixed part of all elements
  int trailing_strings;     // strings after the array
  int64_t max_count;
};

// Walks `n` LCM strings (int32 length including the NUL, the bytes, the NUL) from `pos`.
std::string walk_strings(const uint8_t* p, size_t size, size_t& pos, int64_t n) {
  for (int64_t i = 0; i < n; ++i) {
    if (size - pos < 4) return "truncated";
    const int64_t len = read_be(p + pos, 4);
    pos += 4;
    if (len < 1) return "bad string length";
    if (static_cast<uint64_t>(len) > size - pos) return "string exceeds data";
    if (p[pos + len - 1] != 0) return "string not terminated";
    pos += static_cast<size_t>(len);
  }
  return "";
}

template <class T>
std::string checked_decode(const void* data, size_t size, const Layout& l, T& out) {
  const auto* p = static_cast<const uint8_t*>(data);
  if (!p || size < l.count_offset + 4) return "truncated";
  if (size > kMaxMessageBytes + 4096) return "too large";
  if (read_be(p, 8) != T::getHash()) return "wrong fingerprint";
  const int64_t count = read_be(p + l.count_offset, 4);
  if (count < 0) return "negative count";
  if (count > l.max_count) return "count too large";
  size_t pos = l.count_offset + 4;
  if (static_cast<uint64_t>(count) * l.elem_size > size - pos) return "count exceeds data";
  pos += static_cast<size_t>(count) * l.elem_size;
  if (std::string bad = walk_strings(p, size, pos, count * l.strings_per_elem + l.trailing_strings); !bad.empty())
    return bad;
  if (pos != size) return "trailing bytes";
  try {
    const int n = out.decode(data, 0, static_cast<int>(size));
    if (n < 0) return "truncated";
    if (static_cast<size_t>(n) != size) return "trailing bytes";
  } catch (const std::exception&) {
    return "malformed";
  }
  return "";
}

}  // namespace

std::string check_chunk(const void* data, size_t size, octomap_rt::map_chunk_t& out) {
  return checked_decode(data, size, {kChunkDataSizeOffset, 1, 0, 3, static_cast<int64_t>(kMaxMessageBytes)}, out);
}
std::string check_delta(const void* data, size_t size, octomap_rt::map_delta_t& out) {
  return checked_decode(data, size, {kDeltaDataSizeOffset, 1, 0, 1, static_cast<int64_t>(kMaxMessageBytes)}, out);
}
std::string check_info(const void* data, size_t size, octomap_rt::map_info_t& out) {
  // Each producer: an int64 seq (all seqs first), then one id string each.
  return checked_decode(data, size, {kInfoNumProducersOffset, 8, 1, 2, 4096}, out);
}
std::string check_request(const void* data, size_t size, octomap_rt::map_request_t& out) {
  return checked_decode(data, size, {kRequestNumIndicesOffset, 4, 0, 2, kMaxRequestedChunks}, out);
}

}  // namespace ort::protocol

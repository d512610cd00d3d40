#include "protocol/wire_checks.h"

#include <cstdint>
#include <exception>

#include "protocol/map_protocol.h"

namespace ort::protocol {
namespace {

int64_t read_be(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  if (bytes == 4) return static_cast<int32_t>(static_cast<uint32_t>(v));
  return static_cast<int64_t>(v);
}

struct Layout {
  size_t count_offset;  // of the int32 count, fingerprint included
  size_t elem_size;     // bytes per counted element
  int64_t max_count;
};

template <class T>
std::string checked_decode(const void* data, size_t size, const Layout& l, T& out) {
  const auto* p = static_cast<const uint8_t*>(data);
  if (!p || size < l.count_offset + 4) return "truncated";
  if (size > kMaxMessageBytes + 4096) return "too large";
  if (read_be(p, 8) != T::getHash()) return "wrong fingerprint";
  const int64_t count = read_be(p + l.count_offset, 4);
  if (count < 0) return "negative count";
  if (count > l.max_count) return "count too large";
  if (static_cast<uint64_t>(count) * l.elem_size > size - l.count_offset - 4) return "count exceeds data";
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
  return checked_decode(data, size, {kChunkDataSizeOffset, 1, static_cast<int64_t>(kMaxMessageBytes)}, out);
}
std::string check_delta(const void* data, size_t size, octomap_rt::map_delta_t& out) {
  return checked_decode(data, size, {kDeltaDataSizeOffset, 1, static_cast<int64_t>(kMaxMessageBytes)}, out);
}
std::string check_info(const void* data, size_t size, octomap_rt::map_info_t& out) {
  // Each producer: an int64 seq and a string (4-byte length, >= 1 byte).
  return checked_decode(data, size, {kInfoNumProducersOffset, 13, 4096}, out);
}
std::string check_request(const void* data, size_t size, octomap_rt::map_request_t& out) {
  return checked_decode(data, size, {kRequestNumIndicesOffset, 4, kMaxRequestedChunks}, out);
}

}  // namespace ort::protocol

#include "protocol/wire_layout.h"

namespace ort::protocol {
namespace {

int64_t read_be(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return bytes == 4 ? static_cast<int64_t>(static_cast<int32_t>(static_cast<uint32_t>(v))) : static_cast<int64_t>(v);
}

// One LCM string at `pos` (int32 length including the NUL, the bytes, the NUL).
std::string walk_string(const uint8_t* data, size_t size, size_t& pos, int64_t max_bytes) {
  if (size - pos < 4) return "truncated";
  const int64_t len = read_be(data + pos, 4);
  if (len < 1 || len - 1 > max_bytes) return "bad string length";
  if (static_cast<uint64_t>(len) > size - pos - 4) return "truncated";
  if (data[pos + 4 + static_cast<size_t>(len) - 1] != 0) return "string not terminated";
  pos += 4 + static_cast<size_t>(len);
  return "";
}

}  // namespace

std::string check_wire(const uint8_t* data, size_t size, int64_t hash, std::initializer_list<WireSegment> layout) {
  using S = WireSegment;
  if (!data || size < 8) return "truncated";
  if (read_be(data, 8) != hash) return "wrong fingerprint";
  size_t pos = 8;
  int64_t last_count = 0;
  for (const WireSegment& s : layout) {
    const size_t left = size - pos;
    switch (s.kind) {
      case S::kFixed:
        if (left < static_cast<size_t>(s.size)) return "truncated";
        pos += static_cast<size_t>(s.size);
        break;
      case S::kCount:
        if (left < 4) return "truncated";
        last_count = read_be(data + pos, 4);
        if (last_count < 0) return "negative count";
        if (last_count > s.size) return "count too large (at most " + std::to_string(s.size) + ")";
        pos += 4;
        break;
      case S::kArray:
        if (static_cast<uint64_t>(last_count) * static_cast<uint64_t>(s.size) > left) return "count exceeds data";
        pos += static_cast<size_t>(last_count * s.size);
        break;
      case S::kString:
        if (std::string bad = walk_string(data, size, pos, s.size); !bad.empty()) return bad;
        break;
      case S::kStrings:
        for (int64_t i = 0; i < last_count * s.per; ++i)
          if (std::string bad = walk_string(data, size, pos, s.size); !bad.empty()) return bad;
        break;
    }
  }
  return pos == size ? "" : "trailing bytes";
}

}  // namespace ort::protocol

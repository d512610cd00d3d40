#include "protocol/wire_layout.h"

namespace ort::protocol {
namespace {

int64_t read_be(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return bytes == 4 ? static_cast<int64_t>(static_cast<int32_t>(static_cast<uint32_t>(v))) : static_cast<int64_t>(v);
}

// One LCM string at `pos` (int32 length including the NUL, the bytes, the NUL).
WireFault walk_string(const uint8_t* data, size_t size, size_t& pos, int64_t max_bytes) {
  if (size - pos < 4) return WireFault::kTruncated;
  const int64_t len = read_be(data + pos, 4);
  if (len < 1 || len - 1 > max_bytes) return WireFault::kBadStringLength;
  if (static_cast<uint64_t>(len) > size - pos - 4) return WireFault::kTruncated;
  if (data[pos + 4 + static_cast<size_t>(len) - 1] != 0) return WireFault::kStringNotTerminated;
  pos += 4 + static_cast<size_t>(len);
  return WireFault::kNone;
}

WireCheck fault(WireFault f, int64_t limit = 0) { return {f, limit}; }

}  // namespace

const char* wire_fault_name(WireFault f) {
  switch (f) {
    case WireFault::kNone: return "";
    case WireFault::kTruncated: return "truncated";
    case WireFault::kWrongFingerprint: return "wrong fingerprint";
    case WireFault::kNegativeCount: return "negative count";
    case WireFault::kCountTooLarge: return "count too large";
    case WireFault::kCountExceedsData: return "count exceeds data";
    case WireFault::kBadStringLength: return "bad string length";
    case WireFault::kStringNotTerminated: return "string not terminated";
    case WireFault::kTrailingBytes: return "trailing bytes";
    case WireFault::kTooLarge: return "too large";
    case WireFault::kUndecodable: return "undecodable";
  }
  return "unknown wire fault";
}

std::string describe(const WireCheck& check) {
  std::string text = wire_fault_name(check.fault);
  if (check.fault == WireFault::kCountTooLarge) text += " (at most " + std::to_string(check.limit) + ")";
  if (check.fault == WireFault::kTooLarge) text += " (at most " + std::to_string(check.limit) + " bytes)";
  return text;
}

WireCheck check_wire(const uint8_t* data, size_t size, int64_t hash, std::initializer_list<WireSegment> layout) {
  using S = WireSegment;
  if (!data || size < 8) return fault(WireFault::kTruncated);
  if (read_be(data, 8) != hash) return fault(WireFault::kWrongFingerprint);
  size_t pos = 8;
  int64_t last_count = 0;
  for (const WireSegment& s : layout) {
    const size_t left = size - pos;
    switch (s.kind) {
      case S::kFixed:
        if (left < static_cast<size_t>(s.size)) return fault(WireFault::kTruncated);
        pos += static_cast<size_t>(s.size);
        break;
      case S::kCount:
        if (left < 4) return fault(WireFault::kTruncated);
        last_count = read_be(data + pos, 4);
        if (last_count < 0) return fault(WireFault::kNegativeCount);
        if (last_count > s.size) return fault(WireFault::kCountTooLarge, s.size);
        pos += 4;
        break;
      case S::kArray:
        if (static_cast<uint64_t>(last_count) * static_cast<uint64_t>(s.size) > left)
          return fault(WireFault::kCountExceedsData);
        pos += static_cast<size_t>(last_count * s.size);
        break;
      case S::kString:
        if (WireFault f = walk_string(data, size, pos, s.size); f != WireFault::kNone) return fault(f);
        break;
      case S::kStrings:
        for (int64_t i = 0; i < last_count * s.per; ++i)
          if (WireFault f = walk_string(data, size, pos, s.size); f != WireFault::kNone) return fault(f);
        break;
    }
  }
  return pos == size ? WireCheck{} : fault(WireFault::kTrailingBytes);
}

}  // namespace ort::protocol

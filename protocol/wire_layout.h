// A walk over the raw bytes of one LCM message, by its layout, before decode().
//
// LCM 1.3.1's generated decode() trusts every length it reads: a negative or huge array
// count allocates gigabytes or throws, a corrupt string length makes it read past the buffer
// (INT32_MIN even overflows its `len - 1`). So every inbound message (map protocol, queries,
// edits) is walked here first: the fingerprint, each count within its bound and backed by
// bytes, each string's length within its bound, NUL-terminated, and nothing after the end.
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <string>

namespace ort::protocol {

// One stretch of a message, in encoding order (the .lcm file's field order).
struct WireSegment {
  enum Kind {
    kFixed,    // `size` bytes of fixed-size fields
    kCount,    // an int32 array count, at most `size`
    kArray,    // the last count's elements, `size` bytes each
    kString,   // one string of at most `size` bytes (its int32 length counts the NUL)
    kStrings,  // `per` strings for each element of the last count, each at most `size` bytes
  } kind;
  int64_t size;
  int64_t per = 1;
};

constexpr WireSegment wire_fixed(int64_t bytes) { return {WireSegment::kFixed, bytes}; }
constexpr WireSegment wire_count(int64_t max) { return {WireSegment::kCount, max}; }
constexpr WireSegment wire_array(int64_t elem_bytes) { return {WireSegment::kArray, elem_bytes}; }
constexpr WireSegment wire_string(int64_t max_bytes) { return {WireSegment::kString, max_bytes}; }
constexpr WireSegment wire_strings(int64_t per_elem, int64_t max_bytes) {
  return {WireSegment::kStrings, max_bytes, per_elem};
}

// Why a message's bytes are not one message of its layout (kNone: they are).
enum class WireFault {
  kNone,
  kTruncated,            // the bytes end inside a field
  kWrongFingerprint,     // the first 8 bytes are not the type's hash
  kNegativeCount,        // an array count below zero
  kCountTooLarge,        // an array count above its bound (WireCheck::limit)
  kCountExceedsData,     // an array count with fewer bytes behind it than it needs
  kBadStringLength,      // a string length below 1 (the NUL counts) or above its bound
  kStringNotTerminated,  // a string's last byte is not NUL
  kTrailingBytes,        // bytes after the message's end
  kTooLarge,             // the whole message is above its size bound (WireCheck::limit)
  kUndecodable,          // LCM's decode() refused bytes the walk accepted
};

struct WireCheck {
  WireFault fault = WireFault::kNone;
  int64_t limit = 0;  // for kCountTooLarge, kTooLarge: the bound broken
  bool ok() const { return fault == WireFault::kNone; }
};

// The fault's short name: "truncated", "wrong fingerprint", "negative count", "count too
// large", "count exceeds data", "bad string length", "string not terminated", "trailing
// bytes", "too large", "undecodable"; "" for kNone.
const char* wire_fault_name(WireFault fault);

// The short name with the bound where there is one: "count too large (at most N)", "too
// large (at most N bytes)".
std::string describe(const WireCheck& check);

// Whether the bytes are exactly one message of this layout with the 8-byte fingerprint
// `hash` first, and if not, the first fault in encoding order.
WireCheck check_wire(const uint8_t* data, size_t size, int64_t hash, std::initializer_list<WireSegment> layout);

}  // namespace ort::protocol

#include "protocol/version.h"

#include "protocol/inbound_checks.h"

namespace ort::protocol {
namespace {

uint64_t read_be(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return v;
}

// Versions are small counts; version 1 had no version field, and its bytes 8..11 hold the
// high half of a microsecond timestamp instead (hundreds of thousands).
constexpr int64_t kLargestPlausibleVersion = 9999;

}  // namespace

std::string describe_foreign_version(const uint8_t* data, size_t size, int64_t expected_hash) {
  if (!data || size < kVersionOffset + 4) return "";
  if (static_cast<int64_t>(read_be(data, 8)) == expected_hash) return "";
  const auto version = static_cast<int32_t>(static_cast<uint32_t>(read_be(data + kVersionOffset, 4)));
  const std::string mine = std::to_string(kProtocolVersion);
  if (version >= 1 && version <= kLargestPlausibleVersion && version != kProtocolVersion)
    return "the server speaks protocol version " + std::to_string(version) + ", this program version " + mine +
           ": use a client and server of the same release (docs/PROTOCOL.md, \"Versions\")";
  if (version == kProtocolVersion)
    return "the server says protocol version " + mine +
           " but its message types differ from this program's: a build from another commit of the same release";
  return "the server speaks a protocol older than version 2 (no version field), this program version " + mine +
         ": use a client and server of the same release (docs/PROTOCOL.md, \"Versions\")";
}

}  // namespace ort::protocol

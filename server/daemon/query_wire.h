// Bounds checks on the raw bytes of the query messages, before decode(): LCM 1.3.1's
// generated decode() allocates whatever an array count says and reads strings past the
// buffer's end on a corrupt length. Each query type keeps its fixed-size fields first, then
// its counts and arrays, then its strings; the layouts below follow the .lcm files.
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <string>

namespace ort::daemon {

struct WireSegment {
  enum Kind { kFixed, kCount, kArray, kString } kind;
  int64_t size;  // kFixed: bytes; kCount: largest count allowed; kArray: bytes per counted
                 // element (uses the last count); kString: longest length allowed (bytes)
};

// "" when the bytes are one message of this layout (8-byte fingerprint `hash` first, every
// count within its bound and backed by bytes, strings NUL-terminated, no trailing bytes);
// else why not ("truncated", "wrong fingerprint", "count too large", ...).
std::string check_wire(const uint8_t* data, size_t size, int64_t hash, std::initializer_list<WireSegment> layout);

// Layouts of the inbound query messages, with the server's limits.
constexpr int64_t kMaxQueryPoints = 5000, kMaxQueryRays = 2000, kMaxQueryBoxes = 1000;
std::string check_occupancy_query(const uint8_t* data, size_t size);
std::string check_ray_query(const uint8_t* data, size_t size);
std::string check_box_query(const uint8_t* data, size_t size);
std::string check_grid_query(const uint8_t* data, size_t size);
std::string check_map_edit(const uint8_t* data, size_t size);

}  // namespace ort::daemon

#include "daemon/query_wire.h"

#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/grid_query_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "octomap_rt/occupancy_query_t.hpp"
#include "octomap_rt/ray_query_t.hpp"

namespace ort::daemon {
namespace {

int64_t read_be(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return bytes == 4 ? static_cast<int64_t>(static_cast<int32_t>(v)) : static_cast<int64_t>(v);
}

using S = WireSegment;
constexpr S fixed(int64_t n) { return {S::kFixed, n}; }
constexpr S count(int64_t max) { return {S::kCount, max}; }
constexpr S array(int64_t bytes) { return {S::kArray, bytes}; }
constexpr S str(int64_t max) { return {S::kString, max}; }
// Header common to the queries: utime, request_id, min_snapshot_id, wait_seq, wait_timeout_ms.
constexpr int64_t kHeader = 8 + 8 + 8 + 8 + 4;

}  // namespace

std::string check_wire(const uint8_t* data, size_t size, int64_t hash, std::initializer_list<WireSegment> layout) {
  if (size < 8) return "truncated";
  if (read_be(data, 8) != hash) return "wrong fingerprint";
  size_t pos = 8;
  int64_t last_count = 0;
  for (const WireSegment& s : layout) {
    const size_t left = size - pos;
    switch (s.kind) {
      case S::kFixed:
        if (left < size_t(s.size)) return "truncated";
        pos += s.size;
        break;
      case S::kCount:
        if (left < 4) return "truncated";
        last_count = read_be(data + pos, 4);
        if (last_count < 0) return "negative count";
        if (last_count > s.size) return "count too large (at most " + std::to_string(s.size) + ")";
        pos += 4;
        break;
      case S::kArray:
        if (uint64_t(last_count) * s.size > left) return "count exceeds data";
        pos += last_count * s.size;
        break;
      case S::kString: {
        if (left < 4) return "truncated";
        const int64_t len = read_be(data + pos, 4);  // includes the NUL
        if (len < 1 || len - 1 > s.size) return "bad string length";
        if (uint64_t(len) > left - 4) return "truncated";
        if (data[pos + 4 + len - 1] != 0) return "string not terminated";
        pos += 4 + len;
        break;
      }
    }
  }
  return pos == size ? "" : "trailing bytes";
}

std::string check_occupancy_query(const uint8_t* d, size_t n) {
  return check_wire(d, n, octomap_rt::occupancy_query_t::getHash(),
                    {fixed(kHeader + 4), count(3 * kMaxQueryPoints), array(4), str(64), str(128), str(32)});
}
std::string check_ray_query(const uint8_t* d, size_t n) {
  return check_wire(d, n, octomap_rt::ray_query_t::getHash(),
                    {fixed(kHeader + 1 + 4), count(3 * kMaxQueryRays), array(8), str(64), str(128), str(32)});
}
std::string check_box_query(const uint8_t* d, size_t n) {
  return check_wire(d, n, octomap_rt::box_query_t::getHash(),
                    {fixed(kHeader + 1 + 4 + 1), count(6 * kMaxQueryBoxes), array(8), str(64), str(128), str(32)});
}
std::string check_grid_query(const uint8_t* d, size_t n) {
  return check_wire(d, n, octomap_rt::grid_query_t::getHash(),
                    {fixed(kHeader + 8 * 3 + 1 + 16 + 16), str(64), str(128), str(32)});
}
std::string check_map_edit(const uint8_t* d, size_t n) {
  return check_wire(d, n, octomap_rt::map_edit_t::getHash(), {fixed(8 + 8 + 1 + 48), str(64), str(128), str(256)});
}

}  // namespace ort::daemon

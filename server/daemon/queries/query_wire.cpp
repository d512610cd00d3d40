#include "daemon/queries/query_wire.h"

#include "protocol/wire_layout.h"

#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/grid_query_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "octomap_rt/occupancy_query_t.hpp"
#include "octomap_rt/ray_query_t.hpp"

namespace ort::daemon {
namespace {

// The fault with its bound ("count too large (at most N)"): the text goes back to the client.
std::string check_wire(const uint8_t* d, size_t n, int64_t hash, std::initializer_list<protocol::WireSegment> layout) {
  return protocol::describe(protocol::check_wire(d, n, hash, layout));
}
constexpr auto fixed = protocol::wire_fixed;
constexpr auto count = protocol::wire_count;
constexpr auto array = protocol::wire_array;
constexpr auto str = protocol::wire_string;
// Header common to the queries: utime, request_id, min_snapshot_id, wait_seq, wait_timeout_ms.
constexpr int64_t kHeader = 8 + 8 + 8 + 8 + 4;

}  // namespace

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

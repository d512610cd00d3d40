// libFuzzer target: one raw query message as the query service's LCM handler gets it. The
// first byte picks the type (points, rays, boxes, grid, map edit), the rest is the message.
// Besides memory errors and UB it checks the service's promises: when the raw-byte checks
// pass, the generated decode() consumes the message exactly and does not throw; a query
// that validate_query() accepts is answered on a small map without throwing anything but
// query::QueryError (which the service turns into a BAD_REQUEST reply).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <memory>

#include <octomap/OcTree.h>

#include "daemon/queries/query_answers.h"
#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/grid_query_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "octomap_rt/occupancy_query_t.hpp"
#include "octomap_rt/ray_query_t.hpp"
#include "protocol/inbound_checks.h"
#include "query/query_types.h"

namespace {

using namespace ort::daemon;

// A few occupied and free voxels around the origin at 0.1 m: enough for every query kind
// to find something, small enough that every answer is quick.
const octomap::OcTree& small_map() {
  static const std::unique_ptr<octomap::OcTree> tree = [] {
    auto t = std::make_unique<octomap::OcTree>(0.1);
    for (float x = -1.0f; x <= 1.0f; x += 0.1f) {
      t->updateNode(octomap::point3d(x, 0.5f, 0.2f), true);
      t->updateNode(octomap::point3d(x, -0.5f, 0.2f), false);
    }
    return t;
  }();
  return *tree;
}

// The raw-byte check, then decode(): false when the check refused the bytes.
template <class Message>
bool decoded(const uint8_t* data, size_t size, ort::protocol::WireCheck (*check)(const uint8_t*, size_t),
             Message& msg) {
  if (!check(data, size).ok()) return false;
  try {
    if (msg.decode(data, 0, static_cast<int>(size)) != static_cast<int>(size)) std::abort();
  } catch (const std::exception&) {
    std::abort();  // the raw-byte checks let through what decode() cannot read
  }
  return true;
}

template <class Message>
void exercise(const uint8_t* data, size_t size, ort::protocol::WireCheck (*check)(const uint8_t*, size_t)) {
  Message msg;
  if (!decoded(data, size, check, msg)) return;
  const QueryMessage q(msg);
  (void)header_of(q);
  if (!validate_query(q, 0.1).empty()) return;
  try {
    (void)answer_query(small_map(), q, MapStamp{1, 0}, "fuzz");
  } catch (const ort::query::QueryError&) {
    // answered with BAD_REQUEST by the service
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > 64 * 1024) return 0;  // the service drops messages over 64 KiB first
  const uint8_t kind = data[0] % 5;
  ++data, --size;
  switch (kind) {
    case 0: exercise<octomap_rt::occupancy_query_t>(data, size, ort::protocol::check_occupancy_query_bytes); break;
    case 1: exercise<octomap_rt::ray_query_t>(data, size, ort::protocol::check_ray_query_bytes); break;
    case 2: exercise<octomap_rt::box_query_t>(data, size, ort::protocol::check_box_query_bytes); break;
    case 3: exercise<octomap_rt::grid_query_t>(data, size, ort::protocol::check_grid_query_bytes); break;
    default: {
      octomap_rt::map_edit_t edit;
      (void)decoded(data, size, ort::protocol::check_map_edit_bytes, edit);
      break;
    }
  }
  return 0;
}

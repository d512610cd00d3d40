// libFuzzer target: one raw query message as the query service's LCM handler gets it. The
// first byte picks the type (points, rays, boxes, grid, map edit, distance), the rest is the message.
// Besides memory errors and UB it checks the service's promises: when the raw-byte checks
// pass, the generated decode() consumes the message exactly and does not throw; a query
// that validate_query() accepts is answered on a small map without throwing anything but
// query::QueryError (which the service turns into a BAD_REQUEST reply), and within its cost
// bounds: the work its walks charge, its time under the (would-be) map lock, its reply bytes;
// a distance query that validate_distance() accepts is read and answered without throwing but
// DistanceError.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <memory>

#include <octomap/OcTree.h>

#include "core/clock.h"
#include "daemon/queries/distance_answers.h"
#include "daemon/queries/query_answers.h"
#include "distance/squared_edt.h"
#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/distance_query_t.hpp"
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
  // The cost bounds, tight enough that the fuzzer reaches them on the small map.
  QueryBounds bounds;
  bounds.max_work = 20'000;
  bounds.lock_ms = 10;
  bounds.max_reply_bytes = 256 * 1024;
  ort::query::WorkBudget budget;
  budget.max_work = bounds.max_work;
  budget.deadline = ort::SteadyClock::now() + std::chrono::milliseconds(10);
  const octomap::OcTree& map = small_map();
  const int64_t cpu0 = ort::thread_cpu_ns();
  try {
    const EncodedReplies r = answer_query(map, q, MapStamp{1, 0}, "fuzz", bounds, budget);
    // Bytes: a region or grid's replies within the bound (plus one message's framing).
    size_t bytes = 0;
    for (const auto& m : r.messages) bytes += m.size();
    if (bytes > bounds.max_reply_bytes + 64 * 1024 + 256 * r.messages.size()) std::abort();
  } catch (const ort::query::QueryError&) {
    // answered with BAD_REQUEST by the service
  }
  // Work: what the walks charged stays within the bound, plus one ray's walk bound (a ray is
  // cast whole once admitted; its bound is at most max_work).
  if (budget.used > 2 * bounds.max_work + 1) std::abort();
  // Time under the (would-be) lock: 10x the bound (one ray's walk past the deadline
  // included), generous for sanitizers; CPU time, so that a fuzzer starved of a core on a
  // shared machine does not report the machine.
  if (static_cast<double>(ort::thread_cpu_ns() - cpu0) / 1e6 > 10 * (bounds.lock_ms + 90)) std::abort();
}

void exercise_distance(const uint8_t* data, size_t size) {
  octomap_rt::distance_query_t msg;
  if (!decoded(data, size, ort::protocol::check_distance_query_bytes, msg)) return;
  DistanceServiceConfig cfg;
  cfg.limits.max_grid_cells = 200'000;  // keeps each run quick; the bounds are what is fuzzed
  if (!validate_distance(msg, 0.1, cfg).empty()) return;
  try {
    EncodedReplies r = read_distance(small_map(), msg, MapStamp{1, 0}, "fuzz", cfg, ort::distance::cpu_edt(1));
    r.finish(r);  // refusals after the lock become a reply, never an exception
    if (r.messages.empty()) std::abort();
  } catch (const ort::distance::DistanceError&) {
    // answered with BAD_REQUEST by the service
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > 64 * 1024) return 0;  // the service drops messages over 64 KiB first
  const uint8_t kind = data[0] % 6;
  ++data, --size;
  switch (kind) {
    case 0: exercise<octomap_rt::occupancy_query_t>(data, size, ort::protocol::check_occupancy_query_bytes); break;
    case 1: exercise<octomap_rt::ray_query_t>(data, size, ort::protocol::check_ray_query_bytes); break;
    case 2: exercise<octomap_rt::box_query_t>(data, size, ort::protocol::check_box_query_bytes); break;
    case 3: exercise<octomap_rt::grid_query_t>(data, size, ort::protocol::check_grid_query_bytes); break;
    case 5: exercise_distance(data, size); break;
    default: {
      octomap_rt::map_edit_t edit;
      (void)decoded(data, size, ort::protocol::check_map_edit_bytes, edit);
      break;
    }
  }
  return 0;
}

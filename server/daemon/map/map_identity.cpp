#include "daemon/map/map_identity.h"

#include <random>

#include "daemon/map/map_replica.h"
#include "daemon/map/map_state.h"

namespace ort::daemon {

uint64_t new_map_epoch() {
  std::random_device rd;
  const uint64_t r = (static_cast<uint64_t>(rd()) << 32) ^ rd();
  const uint64_t epoch = r & 0x7fff'ffff'ffff'ffffull;
  return epoch ? epoch : 1;
}

uint64_t count_map_change(MapState& map, std::optional<int64_t> leaf_change) {
  const int64_t leaves = map.leaves.load(std::memory_order_relaxed);
  map.leaves.store(leaves >= 0 && leaf_change ? leaves + *leaf_change : -1, std::memory_order_relaxed);
  return ++map.version;
}

uint64_t fork_map_history(MapState& map) {
  map.epoch = new_map_epoch();
  map.leaves.store(-1, std::memory_order_relaxed);
  return ++map.version;
}

uint64_t apply_map_step(MapState& map, const MapStep& step, bool forks_history) {
  step(*map.tree);
  const uint64_t id = forks_history ? fork_map_history(map) : count_map_change(map);
  if (!map.tree->getRoot()) map.leaves.store(0, std::memory_order_relaxed);
  if (map.replica) map.replica->step_applied(step, map);
  return id;
}

}  // namespace ort::daemon

// The server's map: the octree, the order its scans were applied in, and the lock that
// makes every reader (saves, status, later snapshots and queries) see a state between two
// whole scans. Stage 2 holds the lock for one scan's octree update at a time.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>

#include <octomap/OcTree.h>

#include "daemon/applied_order.h"

namespace ort::daemon {

struct MapState {
  std::mutex mutex;
  std::unique_ptr<octomap::OcTree> tree;
  AppliedOrder order;
  uint64_t version = 0;          // +1 per applied scan (saves skip an unchanged map)
  int64_t last_scan_utime = 0;   // utime of the newest applied scan
};

}  // namespace ort::daemon

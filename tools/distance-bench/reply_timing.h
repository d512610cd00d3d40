// The daemon's box reply stage by stage, in this process on the bench's map: the query as it
// arrives (read_distance under the caller's lock, then its finish: the EDT, the clamp, zstd, the
// chunk messages), once with every field computed whole and once from the field cache with the
// grid unchanged (distance/field_cache.h); what is left after the read and the EDT is the
// reply's encoding. The times between publishing and the reply (LCM, pacing) are the bench's.
#pragma once

#include <cstdint>
#include <string>

#include <octomap/OcTree.h>

#include "distance/distance_types.h"

namespace ort::bench {

struct ReplyTimes {
  double read_ms = 0;    // read_distance (the grid read) of the box query
  double whole_ms = 0;   // its finish, the field computed whole (the EDT, the clamp, encoding)
  double cached_ms = 0;  // its finish from the cache, the grid unchanged (the diff, the clamp, encoding)
  double clamp_ms = 0;   // of those: the box cut out of the field, clamped
  double zstd_ms = 0;    // and its bytes copied and compressed
  // The same by z-slabs on the distance threads (daemon/queries/box_frames.h): every frame
  // made, and every frame kept from the last blob (the clamp alone), with the frames' count.
  double slabs_made_ms = 0, slabs_kept_ms = 0;
  int64_t slab_frames = 0, slab_frames_kept = 0, slab_blob_bytes = 0;
  int64_t blob_bytes = 0, raw_bytes = 0;
  int64_t chunks = 0;
  std::string levels;  // "LEVEL: MS ms BYTES B;" per zstd level tried on the same bytes
};

// Medians over `reps` runs, CPU EDT on `threads` threads, zstd at `zstd_level`.
ReplyTimes time_box_reply(const octomap::OcTree& tree, const double lo[3], const double hi[3],
                          const distance::DistanceOptions& opt, int threads, int zstd_level, int reps);

}  // namespace ort::bench

// A box reply's blob (distance_box_chunk_t's bytes) made of z-slabs compressed apart: the field
// is cut to the box, clamped and compressed slab by slab on the distance threads, and a slab
// whose bytes equal those of the last reply made for the same box keeps that reply's frame,
// so a field that changed in a few slabs costs the clamp of all and the zstd of those few.
//
// zstd frames concatenate: the blob decompresses (ZSTD_decompress, protocol::zstd_decompress,
// a reader across frames) to the same bytes as one frame of the whole (PROTOCOL.md, "Distance
// queries"): the squared distances of every slab in z order, then, when asked, the gradients.
#pragma once

#include <cstdint>
#include <string>

#include "distance/distance_field.h"
#include "distance/distance_queries.h"
#include "distance/field_cache.h"

namespace ort::daemon {

struct BoxBlob {
  std::string bytes;
  int64_t raw_size = 0;     // the bytes once decompressed
  int64_t frames = 0;       // zstd frames in `bytes` (0 without compression)
  int64_t frames_kept = 0;  // of those, taken from `kept` (their slab's bytes unchanged)
};

// Cells a slab holds at most by default (whole z layers; a layer larger than this is a slab
// alone): 256 KiB of distances, so the 30 layers of a 20 x 20 x 3 m box at 0.1 m are 30 frames
// for 16 threads (the blob ~18 % larger than one frame's on scan_dat: each slab compressed alone).
inline constexpr int64_t kSlabCells = 65536;

// The blob of `field` cut to `read`'s box, slabs of at most `slab_cells` cells (0: one slab, made
// on one thread). `kept` (may be null): the frames of the last blob made under `key`, used
// where a slab's bytes are unchanged and replaced by this blob's.
// Throws what zstd throws (protocol::CodecError), after every worker has stopped.
BoxBlob box_blob(const distance::BoxRead& read, const distance::DistanceField& field, bool with_gradient,
                 int zstd_level, int threads, const std::string& key, distance::KeptFrames* kept,
                 int64_t slab_cells = kSlabCells);

}  // namespace ort::daemon

// One served snapshot in one format: the map copy serialized (.ot or .bt), compressed with
// zstd, hashed, with what it contains (map state id, scans, newest seq per producer).
// Built outside the map lock from a MapCopy, so mapping goes on meanwhile.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <octomap/OcTree.h>

#include "daemon/map/map_state.h"

namespace ort::daemon {

struct SnapshotContents {
  uint64_t snapshot_id = 0;  // map state id of the copy
  uint64_t epoch = 0;        // its epoch
  size_t scans = 0;
  int64_t map_utime = 0;
  double bbox_min[3] = {0, 0, 0}, bbox_max[3] = {0, 0, 0};
  // Robot id and newest seq in it, of the kMaxListedProducers producers with the most recent
  // scans in it (most recent first): map_info_t must fit one datagram however many robots
  // the map has seen. producers_total: how many there are.
  std::vector<std::pair<std::string, int64_t>> producer_last_seq;
  int64_t producers_total = 0;
  static constexpr size_t kMaxListedProducers = 64;
  double copy_lock_ms = 0;  // how long taking the copy held the map lock
};

struct SnapshotBlob {
  SnapshotContents contents;
  int8_t format = 0;       // map_chunk_t::FORMAT_*
  int8_t compression = 0;  // map_chunk_t::COMPRESSION_*
  int64_t raw_size = 0;
  std::string bytes;  // compressed
  int64_t hash = 0;   // protocol::blob_hash(bytes)
  double serialize_ms = 0, compress_ms = 0;
  int32_t num_chunks(size_t chunk_bytes) const {
    return static_cast<int32_t>((bytes.size() + chunk_bytes - 1) / chunk_bytes);
  }
};

// What a copy contains: bbox, scans, newest scan time and the newest seq of the producers
// with the most recent scans (MapState::newest_scan at the copy).
SnapshotContents describe_snapshot(const octomap::OcTree& tree,
                                   const std::map<std::string, MapState::NewestScan>& newest_scan, size_t scans,
                                   int64_t map_utime);
// The same without the bbox (the caller sets it: a version of the map knows it, octree/versions/map_version.h).
SnapshotContents describe_snapshot_producers(const std::map<std::string, MapState::NewestScan>& newest_scan,
                                             size_t scans, int64_t map_utime);

// Serializes `tree` (FORMAT_OCTOMAP_FULL: AbstractOcTree::write; FORMAT_OCTOMAP_BINARY:
// OcTree::writeBinary as OctoMap's own .bt, i.e. of a max-likelihood pruned copy) and
// compresses it at `zstd_level` (0: no compression). Throws std::invalid_argument on an
// unknown format.
SnapshotBlob make_snapshot_blob(const octomap::OcTree& tree, const SnapshotContents& contents, int8_t format,
                                int zstd_level);
// The same from the format's bytes already made (`serialize_ms`: the time that took).
SnapshotBlob make_snapshot_blob_of_bytes(std::string raw, const SnapshotContents& contents, int8_t format,
                                         int zstd_level, double serialize_ms);

}  // namespace ort::daemon

#include "daemon/serving/snapshot_blob.h"

#include <algorithm>

#include <chrono>
#include <map>
#include <sstream>
#include <stdexcept>

#include "core/clock.h"
#include "core/file_checks/octree_binary.h"
#include "octomap_rt/map_chunk_t.hpp"
#include "protocol/map_protocol.h"
#include "protocol/zstd_codec.h"

namespace ort::daemon {
namespace {

using Chunk = octomap_rt::map_chunk_t;

std::string serialize(const octomap::OcTree& tree, int8_t format) {
  std::ostringstream out(std::ios::binary);
  if (format == Chunk::FORMAT_OCTOMAP_FULL) {
    // The same bytes as a saved map (AbstractOcTree::write, with log-odds).
    if (!tree.write(out)) throw std::runtime_error("could not serialize the map");
    return std::move(out).str();
  }
  if (format != Chunk::FORMAT_OCTOMAP_BINARY) throw std::invalid_argument("unknown snapshot format");
  // What OcTree::writeBinary writes (max likelihood, pruned), the served copy left as it is.
  return octomap_binary_bytes(tree);
}

}  // namespace

SnapshotContents describe_snapshot_producers(const std::map<std::string, MapState::NewestScan>& newest_scan,
                                             size_t scans, int64_t map_utime) {
  SnapshotContents c;
  c.scans = scans;
  c.map_utime = map_utime;
  std::vector<const MapState::NewestScan*> recent;
  for (const auto& [id, newest] : newest_scan) recent.push_back(&newest);
  std::sort(recent.begin(), recent.end(), [](const auto* a, const auto* b) { return a->scans > b->scans; });
  if (recent.size() > SnapshotContents::kMaxListedProducers) recent.resize(SnapshotContents::kMaxListedProducers);
  for (const auto* r : recent) c.producer_last_seq.push_back({r->robot_id, r->seq});
  c.producers_total = static_cast<int64_t>(newest_scan.size());
  return c;
}

SnapshotContents describe_snapshot(const octomap::OcTree& tree,
                                   const std::map<std::string, MapState::NewestScan>& newest_scan, size_t scans,
                                   int64_t map_utime) {
  SnapshotContents c = describe_snapshot_producers(newest_scan, scans, map_utime);
  if (tree.size() > 0) {
    tree.getMetricMin(c.bbox_min[0], c.bbox_min[1], c.bbox_min[2]);
    tree.getMetricMax(c.bbox_max[0], c.bbox_max[1], c.bbox_max[2]);
  }
  return c;
}

SnapshotBlob make_snapshot_blob(const octomap::OcTree& tree, const SnapshotContents& contents, int8_t format,
                                int zstd_level) {
  const auto t0 = SteadyClock::now();
  std::string raw = serialize(tree, format);
  return make_snapshot_blob_of_bytes(std::move(raw), contents, format, zstd_level, ms_since(t0));
}

SnapshotBlob make_snapshot_blob_of_bytes(std::string raw, const SnapshotContents& contents, int8_t format,
                                         int zstd_level, double serialize_ms) {
  SnapshotBlob b;
  b.contents = contents;
  b.format = format;
  b.serialize_ms = serialize_ms;
  b.raw_size = static_cast<int64_t>(raw.size());
  const auto t0 = SteadyClock::now();
  if (zstd_level > 0) {
    b.bytes = protocol::zstd_compress(raw, zstd_level);
    b.compression = Chunk::COMPRESSION_ZSTD;
  } else {
    b.bytes = std::move(raw);
    b.compression = Chunk::COMPRESSION_NONE;
  }
  b.compress_ms = ms_since(t0);
  b.hash = protocol::blob_hash(b.bytes.data(), b.bytes.size());
  return b;
}

}  // namespace ort::daemon

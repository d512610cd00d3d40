#include "map_client/snapshot_assembly.h"

#include <stdexcept>

#include "protocol/limits.h"
#include "protocol/map_protocol.h"

namespace ort::client {

std::string SnapshotAssembly::add(const octomap_rt::map_chunk_t& c) {
  if (c.num_chunks <= 0 || c.total_size < 0 || c.chunk_size <= 0 ||
      c.chunk_size > static_cast<int32_t>(protocol::kMaxMessageBytes))
    return "bad sizes";
  if (static_cast<int64_t>(c.num_chunks) != (c.total_size + c.chunk_size - 1) / c.chunk_size &&
      !(c.total_size == 0 && c.num_chunks == 1))
    return "chunk count does not match the blob size";
  if (c.uncompressed_size < 0 || c.uncompressed_size > (int64_t{1} << 36)) return "bad uncompressed size";
  if (!started_) {
    started_ = true;
    snapshot_id_ = c.snapshot_id;
    total_size_ = c.total_size;
    hash_ = c.blob_hash;
    uncompressed_size_ = c.uncompressed_size;
    num_scans_ = c.num_scans;
    map_epoch_ = c.map_epoch;
    num_chunks_ = c.num_chunks;
    chunk_size_ = c.chunk_size;
    format_ = c.format;
    compression_ = c.compression;
    parts_.assign(static_cast<size_t>(num_chunks_), {});
    have_.assign(static_cast<size_t>(num_chunks_), false);
  }
  if (c.snapshot_id != snapshot_id_ || c.map_epoch != map_epoch_ || c.total_size != total_size_ ||
      c.blob_hash != hash_ || c.num_chunks != num_chunks_ || c.chunk_size != chunk_size_ || c.format != format_ ||
      c.compression != compression_)
    return "chunk of another snapshot";
  if (c.chunk_index < 0 || c.chunk_index >= num_chunks_) return "chunk index out of range";
  const int64_t offset = static_cast<int64_t>(c.chunk_index) * chunk_size_;
  const int64_t expected = std::min<int64_t>(chunk_size_, total_size_ - offset);
  if (c.offset != offset || c.data_size != expected) return "chunk offset or size wrong";
  if (have_[c.chunk_index]) return "";
  parts_[c.chunk_index].assign(c.data.begin(), c.data.end());
  have_[c.chunk_index] = true;
  received_++;
  received_bytes_ += c.data_size;
  return "";
}

std::vector<int32_t> SnapshotAssembly::missing() const {
  std::vector<int32_t> m;
  for (int32_t i = 0; i < num_chunks_; ++i)
    if (!have_[i]) m.push_back(i);
  return m;
}

std::string SnapshotAssembly::blob() const {
  std::string b;
  b.reserve(static_cast<size_t>(total_size_));
  for (const std::string& p : parts_) b += p;
  if (static_cast<int64_t>(b.size()) != total_size_) throw std::runtime_error("snapshot blob has the wrong size");
  if (protocol::blob_hash(b.data(), b.size()) != hash_)
    throw std::runtime_error("snapshot blob hash mismatch (chunks of different snapshots?)");
  return b;
}

}  // namespace ort::client

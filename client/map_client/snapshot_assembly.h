// Reassembles one snapshot blob from its chunks: checks every chunk against the first
// (same snapshot, sizes, hash), keeps what arrived, names what is missing, and checks the
// whole blob's size and hash at the end.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "octomap_rt/map_chunk_t.hpp"

namespace ort::client {

class SnapshotAssembly {
 public:
  bool started() const { return started_; }
  // Adds a chunk; returns "" when taken (or a duplicate), else why it does not fit.
  std::string add(const octomap_rt::map_chunk_t& c);
  bool complete() const { return started_ && received_ == num_chunks_; }
  std::vector<int32_t> missing() const;
  // The whole blob once complete; throws std::runtime_error when its hash or size is wrong.
  std::string blob() const;

  int64_t snapshot_id() const { return snapshot_id_; }
  int32_t num_chunks() const { return num_chunks_; }
  int32_t received() const { return received_; }
  int64_t total_size() const { return total_size_; }
  int64_t received_bytes() const { return received_bytes_; }
  int64_t uncompressed_size() const { return uncompressed_size_; }
  int64_t num_scans() const { return num_scans_; }
  int64_t map_epoch() const { return map_epoch_; }
  int8_t format() const { return format_; }
  int8_t compression() const { return compression_; }

 private:
  bool started_ = false;
  int64_t snapshot_id_ = 0, total_size_ = 0, hash_ = 0, uncompressed_size_ = 0, num_scans_ = 0, received_bytes_ = 0,
          map_epoch_ = 0;
  int32_t num_chunks_ = 0, chunk_size_ = 0, received_ = 0;
  int8_t format_ = 0, compression_ = 0;
  std::vector<std::string> parts_;
  std::vector<bool> have_;
};

}  // namespace ort::client

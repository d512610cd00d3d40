// The memory bound's store on disk (issue 25): spilled regions (octree/region_codec.h), one
// file each, in a folder beside the map file (FILE.ot.regions/). Crash-safe as the map store:
// a region's bytes go to ID.tmp, are fsynced, renamed to ID.region and the folder fsynced, so
// a region put() returned for survives a kill -9 or a power cut whole, and a crash mid-put
// leaves at most an ID.tmp that the next open removes. The store has its own disk bound, an
// exclusive lock (flock on LOCK: a second daemon on the same map is refused), and a full disk
// (or the bound) refuses the put with kFull and leaves nothing half-written.
#pragma once

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "octree/region_residency.h"

namespace ort::daemon {

class RegionStoreError : public std::runtime_error {
 public:
  enum class Kind {
    kLocked,   // another process holds the store
    kFull,     // the store's bound or the disk is full: nothing was written
    kIo,       // the system refused a read, write, sync or rename (the message says which)
    kCorrupt,  // a region file is not whole (checksum, header)
    kMissing,  // no such region
  };
  RegionStoreError(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

// FILE.ot -> FILE.ot.regions
std::string region_store_dir(const std::string& map_path);

class RegionStore final : public RegionSpill {
 public:
  // Opens `dir` (made if missing), takes its lock, removes leftover .tmp files and counts the
  // regions there. `max_bytes` bounds the regions' bytes on disk. Not `durable`: no fsync (a
  // put still goes through ID.tmp and a rename, and survives a kill -9 in the page cache, not
  // a power cut), for a caller whose files need not outlive the machine's uptime (the
  // daemon: its map file is the map of record, and it empties the store at start).
  RegionStore(const std::string& dir, uint64_t max_bytes, bool durable = true);
  ~RegionStore() override;
  RegionStore(const RegionStore&) = delete;
  RegionStore& operator=(const RegionStore&) = delete;

  void put(RegionId id, std::span<const uint8_t> bytes) override;
  std::vector<uint8_t> get(RegionId id) override;
  void erase(RegionId id) override;

  std::vector<RegionId> ids() const;
  uint64_t used_bytes() const { return used_; }
  uint64_t leftovers_removed() const { return leftovers_removed_; }

 private:
  std::string path_of(RegionId id, const char* ext) const;
  void sync_dir();

  std::string dir_;
  uint64_t max_bytes_;
  bool durable_;
  int lock_fd_ = -1;
  uint64_t used_ = 0, leftovers_removed_ = 0;
  std::unordered_map<RegionId, uint64_t> sizes_;
};

}  // namespace ort::daemon

// One daemon per map file. Two daemons on one --map would share FILE.tmp and the last to
// stop would overwrite the other's map, so the first takes an exclusive lock on FILE.lock
// (flock: released by the kernel when the process ends, however it ends) and writes who it
// is into it; a second one is refused at start with that text.
#pragma once

#include <string>

namespace ort::daemon {

class MapFileLock {
 public:
  MapFileLock() = default;
  // Takes the lock of `map_path` (FILE.lock beside it) and writes `holder` into it. Throws
  // MapStoreError(kLocked) naming the holder, or (kNotWritable) when FILE.lock cannot be
  // created (a missing or read-only directory: the map could not be saved there either).
  MapFileLock(const std::string& map_path, const std::string& holder);
  ~MapFileLock();
  MapFileLock(MapFileLock&& other) noexcept;
  MapFileLock& operator=(MapFileLock&& other) noexcept;
  MapFileLock(const MapFileLock&) = delete;
  MapFileLock& operator=(const MapFileLock&) = delete;

  bool held() const { return fd_ >= 0; }
  const std::string& path() const { return path_; }

 private:
  void release();
  int fd_ = -1;
  std::string path_;
};

// "pid 1234 on host robot-base (octomap-rt-server@robot-base), since 2026-12-01T20:14:02Z":
// what a daemon writes into the lock file.
std::string map_lock_holder(const std::string& server_id, const std::string& host);

}  // namespace ort::daemon

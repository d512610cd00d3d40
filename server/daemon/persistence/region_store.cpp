#include "daemon/persistence/region_store.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "octree/region_codec.h"

namespace ort::daemon {
namespace {

std::string why(const std::string& what, const std::string& path) {
  return what + " " + path + ": " + std::strerror(errno);
}

bool full_disk(int e) { return e == ENOSPC || e == EDQUOT; }

}  // namespace

std::string region_store_dir(const std::string& map_path) { return map_path + ".regions"; }

RegionStore::RegionStore(const std::string& dir, uint64_t max_bytes, bool durable)
    : dir_(dir), max_bytes_(max_bytes), durable_(durable) {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw RegionStoreError(RegionStoreError::Kind::kIo, "cannot make " + dir_ + ": " + ec.message());
  const std::string lock = dir_ + "/LOCK";
  lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd_ < 0) throw RegionStoreError(RegionStoreError::Kind::kIo, why("cannot open", lock));
  if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(lock_fd_);
    lock_fd_ = -1;
    throw RegionStoreError(RegionStoreError::Kind::kLocked,
                           "the region store " + dir_ + " is held by another process (another server on this map?)");
  }
  for (const auto& e : std::filesystem::directory_iterator(dir_)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() == ".tmp") {  // a put that a crash cut short: never returned
      std::filesystem::remove(e.path(), ec);
      leftovers_removed_++;
    } else if (e.path().extension() == ".region") {
      RegionId id = 0;
      if (std::sscanf(name.c_str(), "%" SCNx64 ".region", &id) != 1) continue;
      const uint64_t size = e.file_size();
      sizes_[id] = size;
      used_ += size;
    }
  }
  sync_dir();
}

RegionStore::~RegionStore() {
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the lock
}

std::string RegionStore::path_of(RegionId id, const char* ext) const {
  char name[40];
  std::snprintf(name, sizeof name, "/%012" PRIx64 "%s", id, ext);
  return dir_ + name;
}

void RegionStore::sync_dir() {
  const int fd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) throw RegionStoreError(RegionStoreError::Kind::kIo, why("cannot open", dir_));
  const int r = ::fsync(fd);
  ::close(fd);
  if (r != 0) throw RegionStoreError(RegionStoreError::Kind::kIo, why("cannot fsync", dir_));
}

void RegionStore::put(RegionId id, std::span<const uint8_t> bytes) {
  const auto old = sizes_.find(id);
  const uint64_t replaced = old == sizes_.end() ? 0 : old->second;
  if (used_ - replaced + bytes.size() > max_bytes_)
    throw RegionStoreError(RegionStoreError::Kind::kFull, "the region store " + dir_ + " is at its bound (" +
                                                              std::to_string(used_) + " of " +
                                                              std::to_string(max_bytes_) + " bytes)");
  const std::string tmp = path_of(id, ".tmp"), final_path = path_of(id, ".region");
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw RegionStoreError(full_disk(errno) ? RegionStoreError::Kind::kFull : RegionStoreError::Kind::kIo,
                           why("cannot create", tmp));
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int e = n < 0 ? errno : ENOSPC;
      ::close(fd);
      ::unlink(tmp.c_str());
      errno = e;
      throw RegionStoreError(full_disk(e) ? RegionStoreError::Kind::kFull : RegionStoreError::Kind::kIo,
                             why("cannot write", tmp));
    }
    done += size_t(n);
  }
  if (durable_ && ::fsync(fd) != 0) {
    const int e = errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    errno = e;
    throw RegionStoreError(full_disk(e) ? RegionStoreError::Kind::kFull : RegionStoreError::Kind::kIo,
                           why("cannot fsync", tmp));
  }
  ::close(fd);
  if (::rename(tmp.c_str(), final_path.c_str()) != 0) {
    const std::string msg = why("cannot rename", tmp);
    ::unlink(tmp.c_str());
    throw RegionStoreError(RegionStoreError::Kind::kIo, msg);
  }
  if (durable_) sync_dir();
  used_ = used_ - replaced + bytes.size();
  sizes_[id] = bytes.size();
}

std::vector<uint8_t> RegionStore::get(RegionId id) {
  if (!sizes_.count(id))
    throw RegionStoreError(RegionStoreError::Kind::kMissing, "no region " + std::to_string(id) + " in " + dir_);
  const std::string path = path_of(id, ".region");
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw RegionStoreError(RegionStoreError::Kind::kIo, why("cannot open", path));
  std::vector<uint8_t> bytes(sizes_[id]);
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += size_t(n);
  }
  ::close(fd);
  if (done != bytes.size() || !region_bytes_intact(bytes))
    throw RegionStoreError(RegionStoreError::Kind::kCorrupt, path + " is not a whole region");
  return bytes;
}

void RegionStore::erase(RegionId id) {
  const auto it = sizes_.find(id);
  if (it == sizes_.end()) return;
  const std::string path = path_of(id, ".region");
  if (::unlink(path.c_str()) != 0 && errno != ENOENT)
    throw RegionStoreError(RegionStoreError::Kind::kIo, why("cannot remove", path));
  used_ -= it->second;
  sizes_.erase(it);
  if (durable_) sync_dir();  // not durable: the daemon's restores must not wait for the disk
}

std::vector<RegionId> RegionStore::ids() const {
  std::vector<RegionId> out;
  for (const auto& [id, s] : sizes_) out.push_back(id);
  return out;
}

}  // namespace ort::daemon

#include "daemon/persistence/map_file_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>

#include "core/clock.h"
#include "daemon/persistence/map_store.h"

namespace ort::daemon {
namespace {

std::string read_small_file(int fd) {
  std::string text(512, '\0');
  const ssize_t n = ::pread(fd, text.data(), text.size(), 0);
  text.resize(n > 0 ? static_cast<size_t>(n) : 0);
  while (!text.empty() && (text.back() == '\n' || text.back() == '\0')) text.pop_back();
  return text;
}

}  // namespace

std::string map_lock_holder(const std::string& server_id, const std::string& host) {
  const std::string since = utc_text("%Y-%m-%dT%H:%M:%SZ");
  return "pid " + std::to_string(::getpid()) + " on host " + host + " (" + server_id + "), since " + since;
}

MapFileLock::MapFileLock(const std::string& map_path, const std::string& holder) : path_(map_path + ".lock") {
  fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0)  // the map could not be saved there either
    throw MapStoreError(MapStoreError::Kind::kNotWritable,
                        "the map cannot be saved beside '" + map_path + "' (cannot create its lock file: " +
                            std::strerror(errno) + "); fix the directory or choose another --map");
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    std::string who = read_small_file(fd_);
    ::close(fd_);
    fd_ = -1;
    if (err != EWOULDBLOCK)
      throw MapStoreError(MapStoreError::Kind::kWrite, "cannot lock '" + path_ + "': " + std::strerror(err));
    if (who.empty()) who = "another process (it has not written its name yet)";
    throw MapStoreError(MapStoreError::Kind::kLocked, "the map '" + map_path + "' is in use by " + who +
                                                          "; stop that server or choose another --map");
  }
  const std::string text = holder + "\n";
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, text.data(), text.size(), 0) != static_cast<ssize_t>(text.size())) {
    // The lock holds either way; only the name a second daemon would print is missing.
  }
}

MapFileLock::~MapFileLock() { release(); }

MapFileLock::MapFileLock(MapFileLock&& other) noexcept : fd_(other.fd_), path_(std::move(other.path_)) {
  other.fd_ = -1;
}

MapFileLock& MapFileLock::operator=(MapFileLock&& other) noexcept {
  if (this != &other) {
    release();
    fd_ = other.fd_;
    path_ = std::move(other.path_);
    other.fd_ = -1;
  }
  return *this;
}

// The file stays (removing it would race with a daemon that just opened it to lock it);
// emptied, it names nobody.
void MapFileLock::release() {
  if (fd_ < 0) return;
  if (::ftruncate(fd_, 0) != 0) {}
  ::close(fd_);
  fd_ = -1;
}

}  // namespace ort::daemon

// Runs a piece of a test on a file system of its own: a tmpfs of a given size (a "full
// disk" in a few KiB) or mounted read-only, inside a child process that has its own user and
// mount namespaces (unprivileged; nothing outside the child sees the mount).
#pragma once

#include <cstddef>
#include <functional>
#include <string>

namespace ort::test {

struct SmallFs {
  size_t bytes = 64 * 1024;
  bool read_only = false;
};

// Forks; the child mounts the tmpfs on `dir` (which must exist), runs `body` and exits with
// its return value. Returns that exit status, or -1 when the namespaces or the mount are
// not available here (the caller skips).
int run_on_small_fs(const std::string& dir, const SmallFs& fs, const std::function<int()>& body);

}  // namespace ort::test

#include "support/small_filesystem.h"

#include <sched.h>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <exception>
#include <fstream>

namespace ort::test {
namespace {

void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

}  // namespace

int run_on_small_fs(const std::string& dir, const SmallFs& fs, const std::function<int()>& body) {
  const uid_t uid = ::geteuid();
  const gid_t gid = ::getegid();
  const pid_t pid = ::fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    if (::unshare(CLONE_NEWUSER | CLONE_NEWNS) != 0) ::_exit(200);
    // Map ourselves to root inside, or files we create there have no owner (EOVERFLOW).
    write_text("/proc/self/setgroups", "deny");
    write_text("/proc/self/uid_map", "0 " + std::to_string(uid) + " 1\n");
    write_text("/proc/self/gid_map", "0 " + std::to_string(gid) + " 1\n");
    ::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr);
    const std::string opts = "size=" + std::to_string(fs.bytes);
    const unsigned long flags = fs.read_only ? MS_RDONLY : 0;
    if (::mount("tmpfs", dir.c_str(), "tmpfs", flags, opts.c_str()) != 0) ::_exit(201);
    int rc = 1;
    try {
      rc = body();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "small fs child: uncaught %s\n", e.what());
      rc = 202;
    }
    std::fflush(nullptr);
    ::_exit(rc);
  }
  int st = 0;
  if (::waitpid(pid, &st, 0) != pid) return -1;
  if (!WIFEXITED(st)) return 128 + (WIFSIGNALED(st) ? WTERMSIG(st) : 0);
  const int code = WEXITSTATUS(st);
  return code == 200 || code == 201 ? -1 : code;
}

}  // namespace ort::test

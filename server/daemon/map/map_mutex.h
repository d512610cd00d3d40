// The map's reader-writer lock (MapState::mutex): std::shared_mutex's interface, so that
// std::shared_lock, std::unique_lock, std::lock_guard and condition_variable_any take it as
// they take std::shared_mutex.
//
// Why not std::shared_mutex itself: on glibc it is a pthread rwlock that prefers readers.
// Whole-map readers of the read replica (a snapshot's copy, the viewer's encode, the status'
// figures, query turns) overlap one another; with readers preferred, a writer waits until no
// reader holds the lock at all, which under a steady stream of overlapping readers can be
// never: the replica then falls behind until stage 2 waits for its room. A lock made with
// `prefer_writers()` lets a waiting writer in before any reader that comes after it, so the
// writer waits at most for the readers already inside.
//
// Usage contract: with writers preferred, a thread must never take the lock shared twice
// (a writer waiting between the two holds would deadlock them). try_lock_shared fails while a
// writer waits.
#pragma once

#include <pthread.h>

#include <cerrno>
#include <string>
#include <system_error>

namespace ort::daemon {

class MapMutex {
 public:
  MapMutex() { init(false); }
  ~MapMutex() { pthread_rwlock_destroy(&rw_); }
  MapMutex(const MapMutex&) = delete;
  MapMutex& operator=(const MapMutex&) = delete;

  // Before any thread uses the lock: from now on a waiting writer goes before new readers.
  void prefer_writers() {
    pthread_rwlock_destroy(&rw_);
    init(true);
  }

  void lock() { check(pthread_rwlock_wrlock(&rw_), "lock"); }
  bool try_lock() { return pthread_rwlock_trywrlock(&rw_) == 0; }
  void unlock() { pthread_rwlock_unlock(&rw_); }
  void lock_shared() { check(pthread_rwlock_rdlock(&rw_), "lock_shared"); }
  bool try_lock_shared() { return pthread_rwlock_tryrdlock(&rw_) == 0; }
  void unlock_shared() { pthread_rwlock_unlock(&rw_); }

 private:
  void init(bool writers_first) {
    pthread_rwlockattr_t attr;
    pthread_rwlockattr_init(&attr);
    if (writers_first) pthread_rwlockattr_setkind_np(&attr, PTHREAD_RWLOCK_PREFER_WRITER_NONRECURSIVE_NP);
    check(pthread_rwlock_init(&rw_, &attr), "init");
    pthread_rwlockattr_destroy(&attr);
  }
  static void check(int rc, const char* what) {
    // EDEADLK: this thread holds it already (a defect of the caller, as with std::shared_mutex).
    if (rc != 0) throw std::system_error(rc, std::generic_category(), std::string("map lock: ") + what);
  }
  pthread_rwlock_t rw_;
};

}  // namespace ort::daemon

// The server's one LCM thread and everything that touches LCM's receive side. LCM allows
// only one thread to call handle (lcm-proj/lcm#166), so every service of the server (scan
// intake, map service, query service) registers its raw handlers here instead of owning a
// thread. The thread poll()s LCM's fd together with an eventfd and drains LCM with
// handleTimeout(0), so it never blocks inside LCM and stop() wakes it at once.
//
// Subscriptions are untyped: a handler gets the raw bytes and must validate them before any
// decode() (1.3.1's generated decode throws or allocates gigabytes on corrupt lengths).
// A handler that throws anyway is caught here and counted: nothing escapes into LCM's C
// dispatch, where an exception would be fatal.
//
// When subscriptions may change: 1.3.1's subscribe races with a concurrent handle (the C
// side registers the handler before the C++ side stores it, fixed upstream in PR #273) and
// unsubscribing inside a handler corrupts LCM's dispatch loop (fixed only in 2026). So
// before start() they act at once, and after start() they are posted to the loop thread,
// which runs them between two handle calls while the caller waits. Calling subscribe or
// unsubscribe from inside a handler is refused (std::logic_error).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "core/log.h"

namespace ort::daemon {

// Runs on the loop thread, one message at a time, in subscription order. Keep it cheap
// (validate, copy, queue): every other subscriber waits while it runs.
using RawHandler = std::function<void(const lcm::ReceiveBuffer& rbuf, const std::string& channel)>;

class LcmLoop {
 public:
  using SubscriptionId = uint64_t;

  // Own LCM on `url`. Throws std::runtime_error when LCM cannot start there (the message
  // says how to give loopback a multicast route).
  LcmLoop(const std::string& url, Log log);
  // On a shared LCM (tests: one memq:// instance with in-process producers). The loop's
  // thread must be the only one that calls handle on it.
  LcmLoop(lcm::LCM& shared, Log log);
  ~LcmLoop();
  LcmLoop(const LcmLoop&) = delete;
  LcmLoop& operator=(const LcmLoop&) = delete;

  // Untyped subscription to a channel regex (anchored, POSIX extended, as LCM's). LCM's own
  // queue for it holds `queue_capacity` messages (0: unlimited; LCM drops the newest when
  // full, silently, so keep handlers quick and the capacity generous). Throws
  // std::runtime_error when LCM refuses, std::logic_error from inside a handler.
  SubscriptionId subscribe(const std::string& channel_regex, RawHandler handler, int queue_capacity = 64);
  // After it returns, the handler is not running and will not run again.
  void unsubscribe(SubscriptionId id);

  // Starts the thread. Subscribe what must not miss a message before this.
  void start();
  // Wakes and joins the thread, then unsubscribes everything. Idempotent.
  void stop();

  // Publishes from any thread, including handlers. Serialized by the loop's own mutex: udpm
  // and memq are internally synchronized in 1.3.1, but tcpq's publish is not (lcm#614).
  // Returns LCM's result (0: sent).
  int publish(const std::string& channel, const void* data, size_t size);
  template <class Message>
  int publish(const std::string& channel, const Message& msg) {
    std::vector<uint8_t> buf(static_cast<size_t>(msg.getEncodedSize()));
    if (msg.encode(buf.data(), 0, static_cast<int>(buf.size())) < 0) return -1;
    return publish(channel, buf.data(), buf.size());
  }

  // True once LCM's handle failed or poll failed (the thread has then exited).
  bool failed() const { return failed_; }
  int64_t messages_handled() const { return handled_; }
  int64_t handler_errors() const { return handler_errors_; }

 private:
  struct Entry;
  void run();
  bool drain_lcm();
  void run_posted();
  // Runs f on the loop thread between two handle calls (at once before start or after stop).
  void on_loop(const std::function<void()>& f);
  void do_subscribe(Entry& e);
  void do_unsubscribe(SubscriptionId id);
  void wake();

  Log log_;
  std::unique_ptr<lcm::LCM> own_;
  lcm::LCM& lc_;
  int wake_fd_ = -1;
  std::thread thread_;
  std::atomic<std::thread::id> loop_thread_id_{};
  std::atomic<bool> failed_{false}, stopping_{false};
  std::atomic<int64_t> handled_{0}, handler_errors_{0};

  std::mutex mutex_;  // entries_, posted_, running_
  std::condition_variable posted_done_;
  std::list<Entry> entries_;  // stable addresses: LCM keeps a pointer to each
  std::vector<std::function<void()>> posted_;
  uint64_t next_id_ = 1, posted_seq_ = 0, done_seq_ = 0;
  bool running_ = false;

  std::mutex publish_mutex_;
};

}  // namespace ort::daemon

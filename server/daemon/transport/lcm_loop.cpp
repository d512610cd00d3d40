#include "daemon/transport/lcm_loop.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <exception>
#include <stdexcept>

namespace ort::daemon {

struct LcmLoop::Entry {
  SubscriptionId id = 0;
  std::string regex;
  RawHandler handler;
  int queue_capacity = 0;
  lcm::Subscription* sub = nullptr;
  LcmLoop* loop = nullptr;

  // Called from LCM's C dispatch: nothing may throw out of here.
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    loop->handled_++;
    try {
      handler(*rbuf, channel);
    } catch (const std::exception& e) {
      loop->handler_errors_++;
      loop->log_.error(text("unexpected error on ", channel, ": ", e.what()));
    } catch (...) {
      loop->handler_errors_++;
      loop->log_.error(text("unexpected error on ", channel));
    }
  }
};

namespace {

lcm::LCM& open_lcm(std::unique_ptr<lcm::LCM>& own, const std::string& url) {
  own = std::make_unique<lcm::LCM>(url);
  if (!own->good())
    throw std::runtime_error("LCM could not start on '" + url +
                             "' (for udpm on one host: ip route add 224.0.0.0/4 dev lo, see LCM's multicast setup)");
  return *own;
}

int make_eventfd() {
  const int fd = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (fd < 0) throw std::runtime_error(std::string("eventfd: ") + std::strerror(errno));
  return fd;
}

}  // namespace

LcmLoop::LcmLoop(const std::string& url, Log log) : log_(std::move(log)), lc_(open_lcm(own_, url)) {
  wake_fd_ = make_eventfd();
}

LcmLoop::LcmLoop(lcm::LCM& shared, Log log) : log_(std::move(log)), lc_(shared) { wake_fd_ = make_eventfd(); }

LcmLoop::~LcmLoop() {
  stop();
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

LcmLoop::SubscriptionId LcmLoop::subscribe(const std::string& channel_regex, RawHandler handler, int queue_capacity) {
  Entry* e = nullptr;
  {
    std::lock_guard lock(mutex_);
    e = &entries_.emplace_back();
    e->id = next_id_++;
    e->regex = channel_regex;
    e->handler = std::move(handler);
    e->queue_capacity = queue_capacity;
    e->loop = this;
  }
  try {
    on_loop([&] { do_subscribe(*e); });
  } catch (...) {
    std::lock_guard lock(mutex_);
    entries_.remove_if([&](const Entry& x) { return &x == e; });
    throw;
  }
  return e->id;
}

void LcmLoop::unsubscribe(SubscriptionId id) {
  on_loop([&] { do_unsubscribe(id); });
}

void LcmLoop::do_subscribe(Entry& e) {
  e.sub = lc_.subscribe(e.regex, &Entry::on_message, &e);
  if (!e.sub) throw std::runtime_error("LCM: cannot subscribe to '" + e.regex + "'");
  e.sub->setQueueCapacity(e.queue_capacity);
}

// Runs with no handle in progress (loop thread between handles, or no thread).
void LcmLoop::do_unsubscribe(SubscriptionId id) {
  for (auto it = entries_.begin(); it != entries_.end(); ++it) {
    if (it->id != id) continue;
    if (it->sub) lc_.unsubscribe(it->sub);
    entries_.erase(it);
    return;
  }
}

void LcmLoop::on_loop(const std::function<void()>& f) {
  if (std::this_thread::get_id() == loop_thread_id_.load())
    throw std::logic_error("LcmLoop: subscribe/unsubscribe from inside a handler (LCM 1.3.1 cannot)");
  std::unique_lock lock(mutex_);
  if (!running_) {
    f();  // no thread handles: safe here (the lock keeps start() from racing with it)
    return;
  }
  std::exception_ptr error;
  posted_.push_back([&] {
    try {
      f();
    } catch (...) {
      error = std::current_exception();
    }
  });
  const uint64_t mine = ++posted_seq_;
  wake();
  posted_done_.wait(lock, [&] { return done_seq_ >= mine; });
  if (error) std::rethrow_exception(error);
}

// Under mutex_.
void LcmLoop::run_posted() {
  for (auto& f : posted_) f();
  done_seq_ += posted_.size();
  posted_.clear();
  posted_done_.notify_all();
}

void LcmLoop::wake() {
  const uint64_t one = 1;
  if (::write(wake_fd_, &one, sizeof one) < 0) log_.error("eventfd write failed");
}

void LcmLoop::start() {
  std::lock_guard lock(mutex_);
  if (running_ || thread_.joinable() || stopping_) return;
  running_ = true;
  thread_ = std::thread([this] { run(); });
}

void LcmLoop::stop() {
  stopping_ = true;
  if (thread_.joinable()) {
    wake();
    thread_.join();
  }
  std::lock_guard lock(mutex_);
  for (Entry& e : entries_)
    if (e.sub) lc_.unsubscribe(e.sub);
  entries_.clear();
}

bool LcmLoop::drain_lcm() {
  int r;
  while ((r = lc_.handleTimeout(0)) > 0) {}
  return r >= 0;
}

void LcmLoop::run() {
  loop_thread_id_ = std::this_thread::get_id();
  pollfd fds[2] = {{lc_.getFileno(), POLLIN, 0}, {wake_fd_, POLLIN, 0}};
  for (;;) {
    const int n = ::poll(fds, 2, -1);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      log_.error(text("poll: ", std::strerror(errno)));
      failed_ = true;
      break;
    }
    if (fds[1].revents) {
      uint64_t count = 0;
      if (::read(wake_fd_, &count, sizeof count) < 0 && errno != EAGAIN) log_.error("eventfd read failed");
      std::lock_guard lock(mutex_);
      run_posted();
      if (stopping_) break;
    }
    if (fds[0].revents && !drain_lcm()) {
      log_.error("LCM handle failed; the LCM thread stopped");
      failed_ = true;
      break;
    }
  }
  // From here on, subscription changes act at once (on the caller's thread).
  std::lock_guard lock(mutex_);
  running_ = false;
  run_posted();
  loop_thread_id_ = std::thread::id();
}

int LcmLoop::publish(const std::string& channel, const void* data, size_t size) {
  std::lock_guard lock(publish_mutex_);
  return lc_.publish(channel, data, static_cast<unsigned>(size));
}

}  // namespace ort::daemon

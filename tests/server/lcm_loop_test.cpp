// The server's LCM loop over memq:// in one process: raw subscriptions before and after
// start, unsubscribe, a throwing handler counted instead of crashing, subscribe refused
// inside a handler, publish from several threads, and a prompt stop.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "daemon/transport/lcm_loop.h"

namespace ort::test {
namespace {

using daemon::LcmLoop;

// Counts messages per handler and lets a test wait for a count.
struct Counter {
  std::mutex m;
  std::condition_variable cv;
  int n = 0;
  std::vector<std::string> payloads;
  void hit(const lcm::ReceiveBuffer& rb) {
    std::lock_guard lock(m);
    ++n;
    payloads.emplace_back(static_cast<const char*>(rb.data), rb.data_size);
    cv.notify_all();
  }
  bool wait_for(int want) {
    std::unique_lock lock(m);
    return cv.wait_for(lock, std::chrono::seconds(10), [&] { return n >= want; });
  }
  int count() {
    std::lock_guard lock(m);
    return n;
  }
};

void send(lcm::LCM& lc, const std::string& channel, const std::string& payload) {
  lc.publish(channel, payload.data(), static_cast<unsigned>(payload.size()));
}

TEST(LcmLoop, HandlersGetRawBytesOfTheirChannelsOnly) {
  lcm::LCM lc("memq://");
  ASSERT_TRUE(lc.good());
  std::ostringstream log;
  LcmLoop loop(lc, log);
  Counter scans, requests;
  loop.subscribe("SCAN_.*", [&](const lcm::ReceiveBuffer& rb, const std::string&) { scans.hit(rb); });
  loop.subscribe("REQUEST", [&](const lcm::ReceiveBuffer& rb, const std::string&) { requests.hit(rb); });
  loop.start();
  send(lc, "SCAN_A", "one");
  send(lc, "REQUEST", "two");
  send(lc, "SCAN_B", "three");
  send(lc, "OTHER", "four");
  ASSERT_TRUE(scans.wait_for(2));
  ASSERT_TRUE(requests.wait_for(1));
  loop.stop();
  EXPECT_EQ(scans.payloads, (std::vector<std::string>{"one", "three"}));
  EXPECT_EQ(requests.payloads, (std::vector<std::string>{"two"}));
  EXPECT_EQ(loop.messages_handled(), 3);
}

TEST(LcmLoop, SubscribeAndUnsubscribeWhileRunning) {
  lcm::LCM lc("memq://");
  std::ostringstream log;
  LcmLoop loop(lc, log);
  Counter first, late;
  const auto id = loop.subscribe("A", [&](const lcm::ReceiveBuffer& rb, const std::string&) { first.hit(rb); });
  loop.start();
  loop.subscribe("B", [&](const lcm::ReceiveBuffer& rb, const std::string&) { late.hit(rb); });
  send(lc, "B", "x");
  ASSERT_TRUE(late.wait_for(1));
  send(lc, "A", "y");
  ASSERT_TRUE(first.wait_for(1));
  loop.unsubscribe(id);
  send(lc, "A", "z");
  send(lc, "B", "w");
  ASSERT_TRUE(late.wait_for(2));  // B's message came after A's, so A's was handled (or not) by now
  EXPECT_EQ(first.count(), 1);
}

TEST(LcmLoop, ThrowingHandlerIsCountedAndTheLoopGoesOn) {
  lcm::LCM lc("memq://");
  std::ostringstream log;
  LcmLoop loop(lc, log);
  Counter after;
  loop.subscribe("BAD", [](const lcm::ReceiveBuffer&, const std::string&) { throw std::runtime_error("boom"); });
  loop.subscribe("GOOD", [&](const lcm::ReceiveBuffer& rb, const std::string&) { after.hit(rb); });
  loop.start();
  send(lc, "BAD", "1");
  send(lc, "GOOD", "2");
  ASSERT_TRUE(after.wait_for(1));
  loop.stop();
  EXPECT_EQ(loop.handler_errors(), 1);
  EXPECT_FALSE(loop.failed());
  EXPECT_NE(log.str().find("boom"), std::string::npos);
}

TEST(LcmLoop, SubscribeInsideAHandlerIsRefused) {
  lcm::LCM lc("memq://");
  std::ostringstream log;
  LcmLoop loop(lc, log);
  Counter done;
  std::atomic<bool> refused{false};
  loop.subscribe("X", [&](const lcm::ReceiveBuffer& rb, const std::string&) {
    try {
      loop.subscribe("Y", [](const lcm::ReceiveBuffer&, const std::string&) {});
    } catch (const std::logic_error&) {
      refused = true;
    }
    done.hit(rb);
  });
  loop.start();
  send(lc, "X", "1");
  ASSERT_TRUE(done.wait_for(1));
  EXPECT_TRUE(refused);
}

TEST(LcmLoop, PublishFromSeveralThreadsWhileHandling) {
  lcm::LCM lc("memq://");
  std::ostringstream log;
  LcmLoop loop(lc, log);
  Counter got;
  loop.subscribe("OUT", [&](const lcm::ReceiveBuffer& rb, const std::string&) { got.hit(rb); });
  loop.start();
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < 50; ++i) EXPECT_EQ(loop.publish("OUT", std::string(100 + t, 'a' + t).data(), 100 + t), 0);
    });
  for (auto& th : threads) th.join();
  ASSERT_TRUE(got.wait_for(200));
  for (const std::string& p : got.payloads) EXPECT_EQ(p, std::string(p.size(), p[0]));
}

TEST(LcmLoop, StopWakesAnIdleLoopAndUnsubscribes) {
  lcm::LCM lc("memq://");
  std::ostringstream log;
  Counter got;
  {
    LcmLoop loop(lc, log);
    loop.subscribe("A", [&](const lcm::ReceiveBuffer& rb, const std::string&) { got.hit(rb); });
    loop.start();
    loop.stop();  // returns although no message ever arrives
    loop.stop();  // idempotent
  }
  send(lc, "A", "after");
  EXPECT_EQ(lc.handleTimeout(50), 0);  // nobody subscribed any more: nothing to dispatch
  EXPECT_EQ(got.count(), 0);
}

}  // namespace
}  // namespace ort::test

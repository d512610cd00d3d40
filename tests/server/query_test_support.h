// What the query service's in-process tests share (memq://): a collector of replies on the
// test's reply channel, addressed queries, and robot "alpha"'s wall scans.
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/clock.h"
#include "octomap_rt/map_edit_t.hpp"
#include "octomap_rt/occupancy_query_t.hpp"
#include "octomap_rt/occupancy_reply_t.hpp"
#include "protocol/channels.h"
#include "protocol/edit_mac.h"
#include "server/scan_fixtures.h"

namespace ort::test {

using Reply = octomap_rt::occupancy_reply_t;
inline const std::string kReply = "QUERY_TEST_REPLY";

// Collects raw messages on the reply channel through the server's own LCM loop (on a
// shared memq:// instance only the server's thread may call handle).
struct Replies {
  std::mutex m;
  std::condition_variable cv;
  std::vector<std::vector<uint8_t>> got;
  explicit Replies(daemon::MappingServer& s) {
    s.lcm_loop().subscribe(kReply, [this](const lcm::ReceiveBuffer& rb, const std::string&) {
      std::lock_guard lock(m);
      got.emplace_back(static_cast<const uint8_t*>(rb.data), static_cast<const uint8_t*>(rb.data) + rb.data_size);
      cv.notify_all();
    });
  }
  // The first reply of type M with this request id (fails the test after 20 s).
  template <class M>
  M wait_for(int64_t request_id) {
    std::unique_lock lock(m);
    M out;
    const bool ok = cv.wait_for(lock, std::chrono::seconds(20), [&] {
      for (const auto& b : got)
        if (out.decode(b.data(), 0, static_cast<int>(b.size())) >= 0 && out.request_id == request_id) return true;
      return false;
    });
    EXPECT_TRUE(ok) << "no reply to request " << request_id;
    return out;
  }
};

template <class Q>
void address(Q& q, int64_t id, const std::string& client = "tester") {
  q.request_id = id;
  q.wait_seq = -1;
  q.client_id = client;
  q.reply_channel = kReply;
}

inline octomap_rt::occupancy_query_t point_query(int64_t id, const std::vector<float>& xyz,
                                                 const std::string& client = "tester") {
  octomap_rt::occupancy_query_t q{};
  address(q, id, client);
  q.xyz = xyz;
  q.num_xyz = static_cast<int32_t>(xyz.size());
  return q;
}

inline const std::string kToken = "correct horse battery staple";

// Stamps the edit now with a fresh nonce and signs it with `token` (as a client does).
inline void sign(octomap_rt::map_edit_t& e, const std::string& token = kToken) {
  e.utime = now_utime();
  e.nonce = protocol::random_edit_nonce();
  protocol::sign_edit(e, token, ort::protocol::kMapEditChannel);
}

// A server over memq:// started with `cfg`; the replies to the test's queries and edits
// collected, the server's log kept.
struct QueryServer {
  lcm::LCM lc{"memq://"};
  std::ostringstream log;
  daemon::MappingServer server;
  Replies replies;
  explicit QueryServer(const daemon::ServerConfig& cfg = test_config(0.1, true))
      : server(cfg, lc, log), replies(server) {
    server.start();
  }
};

// `c` with map edits on, signed with kToken.
inline daemon::ServerConfig with_edits(daemon::ServerConfig c) {
  c.queries.control_token = kToken;
  return c;
}

// Scan k of robot "alpha": a wall of points at x = 3 + k (map frame), sensor at the origin.
inline octomap_rt::scan_t wall_scan(int64_t k) {
  octomap_rt::scan_t s = small_scan("alpha", k, 1);
  s.points_frame = octomap_rt::scan_t::POINTS_IN_MAP_FRAME;
  s.sensor_position[0] = s.sensor_position[1] = s.sensor_position[2] = 0;
  s.xyz.clear();
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 10; ++j) s.xyz.insert(s.xyz.end(), {3.05f + k, -1.f + 0.1f * i, 0.05f + 0.1f * j});
  s.num_xyz = static_cast<int32_t>(s.xyz.size());
  return s;
}

}  // namespace ort::test

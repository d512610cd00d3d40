// Distance queries through the daemon in one process over memq://: points, a dense box
// (chunks, hash, zstd) and a path, each answered from the map state just written
// (read-your-writes) and equal to server/distance/ on the server's own map; bad queries
// refused with the bound or field that refused them, and counted; the Vulkan EDT gives the
// same box (skipped without a device).
#include <gtest/gtest.h>

#include <cstring>

#include "core/errors.h"
#include "distance/distance_queries.h"
#include "distance/squared_edt.h"
#include "gpu/distance_transform.h"
#include "octomap_rt/distance_box_chunk_t.hpp"
#include "octomap_rt/distance_path_reply_t.hpp"
#include "octomap_rt/distance_points_reply_t.hpp"
#include "octomap_rt/distance_query_t.hpp"
#include "protocol/channels.h"
#include "protocol/limits.h"
#include "protocol/map_protocol.h"
#include "protocol/zstd_codec.h"
#include "server/query_test_support.h"
#include "server/scan_fixtures.h"

namespace ort::test {
namespace {

using DQ = octomap_rt::distance_query_t;

DQ distance_query(int64_t id, int8_t mode, double max_distance) {
  DQ q{};
  address(q, id);
  q.mode = mode;
  q.max_distance = max_distance;
  q.cell_voxels = 1;
  return q;
}

// The box's chunks assembled, checked and decompressed: squared distances, then gradients.
struct Field {
  octomap_rt::distance_box_chunk_t first;
  std::vector<uint32_t> squared;
  std::vector<float> gradient;
};
Field assemble(Replies& replies, int64_t id) {
  Field f;
  f.first = replies.wait_for<octomap_rt::distance_box_chunk_t>(id);
  if (f.first.status != Reply::REPLY_OK) return f;
  std::string blob(size_t(f.first.total_size), '\0');
  for (int32_t c = 0; c < f.first.num_chunks; ++c) {
    // Chunks of one request arrive in order; wait until chunk c is in.
    octomap_rt::distance_box_chunk_t m;
    for (int tries = 0; tries < 2000; ++tries) {
      bool found = false;
      {
        std::lock_guard lock(replies.m);
        for (const auto& b : replies.got)
          if (m.decode(b.data(), 0, int(b.size())) >= 0 && m.request_id == id && m.chunk_index == c) {
            found = true;
            break;
          }
      }
      if (found) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    EXPECT_EQ(m.chunk_index, c);
    std::memcpy(blob.data() + size_t(c) * protocol::kChunkDataBytes, m.data.data(), m.data.size());
  }
  EXPECT_EQ(protocol::blob_hash(blob.data(), blob.size()), f.first.blob_hash);
  const std::string raw = f.first.compression == f.first.COMPRESSION_ZSTD
                              ? protocol::zstd_decompress(blob, size_t(f.first.uncompressed_size))
                              : blob;
  const size_t cells = size_t(f.first.size[0]) * f.first.size[1] * f.first.size[2];
  f.squared.resize(cells);
  std::memcpy(f.squared.data(), raw.data(), cells * 4);
  if (f.first.with_gradient) {
    f.gradient.resize(3 * cells);
    std::memcpy(f.gradient.data(), raw.data() + cells * 4, cells * 12);
  }
  return f;
}

void run_queries(daemon::MappingServer& server, lcm::LCM& lc, Replies& replies) {
  distance::DistanceOptions opt;
  opt.max_distance = 1.55;
  for (int64_t k = 0; k < 3; ++k) {
    const octomap_rt::scan_t scan = wall_scan(k);
    lc.publish("OCTOMAP_RT_SCAN_ALPHA", &scan);
    // Points in front of the wall just sent, waiting for that scan.
    DQ q = distance_query(100 + k, DQ::MODE_POINTS, opt.max_distance);
    q.with_gradient = 1;
    q.wait_robot_id = "alpha", q.wait_seq = k, q.wait_timeout_ms = 20000;
    q.xyz = {float(2.05 + k), 0.05f, 0.55f, float(2.55 + k), -0.35f, 0.25f, -4.f, 7.f, 1.f};
    q.num_xyz = int32_t(q.xyz.size());
    lc.publish(protocol::kQueryDistanceChannel, &q);
    const auto r = replies.wait_for<octomap_rt::distance_points_reply_t>(100 + k);
    ASSERT_EQ(r.status, Reply::REPLY_OK) << r.error;
    EXPECT_GE(r.snapshot_id, k + 1);
    // The epoch of the history the state id counts in: the server's (never 0).
    const int64_t epoch = server.status().map_epoch;
    EXPECT_NE(epoch, 0);
    EXPECT_EQ(r.map_epoch, epoch);
    ASSERT_EQ(r.num_points, 3);
    ASSERT_EQ(r.num_gradient, 9);
    if (k == 0) {                             // (later walls stand where earlier points were)
      EXPECT_FLOAT_EQ(r.distance[0], 1.0f);   // ten voxels in front of the wall's middle
      EXPECT_FLOAT_EQ(r.gradient[0], -1.0f);  // nearer to the wall along +x
    }
    EXPECT_FLOAT_EQ(r.distance[2], 1.55f);  // nothing within reach: the clamp
    const auto want = server.with_map([&](const octomap::OcTree& t) {
      return distance::answer_points(distance::read_points(t, q.xyz, opt, {}), distance::cpu_edt(1));
    });
    for (int p = 0; p < 3; ++p) {
      EXPECT_EQ(r.distance[p], want[p].distance) << p;
      for (int a = 0; a < 3; ++a) EXPECT_EQ(r.gradient[3 * p + a], want[p].gradient[a]);
    }
  }
  // A dense box, at the resolution and at 2 voxels a cell, unknown as occupied.
  int64_t id = 300;
  for (int m : {1, 2}) {
    DQ q = distance_query(++id, DQ::MODE_BOX, opt.max_distance);
    q.with_gradient = 1, q.cell_voxels = m, q.unknown_as = DQ::UNKNOWN_OCCUPIED;
    const double lo[3] = {1.0, -1.5, 0.0}, hi[3] = {6.0, 1.5, 1.0};
    std::copy(lo, lo + 3, q.box_min), std::copy(hi, hi + 3, q.box_max);
    lc.publish(protocol::kQueryDistanceChannel, &q);
    const Field f = assemble(replies, id);
    ASSERT_EQ(f.first.status, Reply::REPLY_OK) << f.first.error;
    distance::DistanceOptions bo = opt;
    bo.cell_voxels = m, bo.unknown = distance::UnknownAs::kOccupied;
    const auto want = server.with_map([&](const octomap::OcTree& t) {
      return distance::answer_box(distance::read_box(t, lo, hi, bo, {}), distance::cpu_edt(1), true);
    });
    EXPECT_EQ(f.first.map_epoch, server.status().map_epoch);
    EXPECT_EQ(f.first.size[0], want.cells.dims.nx);
    EXPECT_DOUBLE_EQ(f.first.cell_size, 0.1 * m);
    EXPECT_DOUBLE_EQ(f.first.origin[0], want.origin[0]);
    EXPECT_EQ(f.squared, want.squared);
    EXPECT_EQ(f.gradient, want.gradient);
  }
  // A path along the wall: its clearance and where.
  {
    DQ q = distance_query(++id, DQ::MODE_PATH, opt.max_distance);
    q.xyz = {1.0f, -2.0f, 0.5f, 3.5f, -0.2f, 0.5f, 3.6f, 2.0f, 0.5f};
    q.num_xyz = 9;
    lc.publish(protocol::kQueryDistanceChannel, &q);
    const auto r = replies.wait_for<octomap_rt::distance_path_reply_t>(id);
    ASSERT_EQ(r.status, Reply::REPLY_OK) << r.error;
    const std::vector<double> v(q.xyz.begin(), q.xyz.end());
    const auto want = server.with_map([&](const octomap::OcTree& t) {
      return distance::answer_path(distance::read_path(t, v, opt, {}), distance::cpu_edt(1));
    });
    EXPECT_EQ(r.map_epoch, server.status().map_epoch);
    EXPECT_EQ(r.num_samples, want.num_samples);
    EXPECT_EQ(r.min_sample, want.min_sample);
    EXPECT_FLOAT_EQ(float(r.min_distance), want.min_distance);
    EXPECT_LT(r.min_distance, 0.5);  // the path passes the wall at 3.05 .. 5.05
  }
}

TEST(DistanceQueries, PointsBoxAndPathFromTheStateJustWritten) {
  QueryServer fixture;
  auto& [lc, log, server, replies] = fixture;
  run_queries(server, lc, replies);

  // Refusals, each with what refused it.
  struct Bad {
    DQ q;
    std::string says;
  };
  std::vector<Bad> bad;
  bad.push_back({distance_query(901, DQ::MODE_POINTS, 0.0), "max_distance"});
  bad.push_back({distance_query(902, 7, 1.0), "unknown mode"});
  bad.push_back({distance_query(903, DQ::MODE_BOX, 1.0), "at most"});
  bad.back().q.box_min[0] = bad.back().q.box_min[1] = -100, bad.back().q.box_max[0] = bad.back().q.box_max[1] = 100;
  bad.push_back({distance_query(904, DQ::MODE_BOX, 1.0), "cell_voxels"});
  bad.back().q.cell_voxels = 0;
  bad.push_back({distance_query(905, DQ::MODE_PATH, 1.0), "at least one vertex"});
  bad.push_back({distance_query(906, DQ::MODE_POINTS, 1.0), "not finite"});
  bad.back().q.xyz = {0, NAN, 0}, bad.back().q.num_xyz = 3;
  for (Bad& b : bad) lc.publish(protocol::kQueryDistanceChannel, &b.q);
  for (Bad& b : bad) {
    std::string error;
    int8_t status = 0;
    if (b.q.mode == DQ::MODE_BOX) {
      const auto r = replies.wait_for<octomap_rt::distance_box_chunk_t>(b.q.request_id);
      error = r.error, status = r.status;
    } else if (b.q.mode == DQ::MODE_PATH) {
      const auto r = replies.wait_for<octomap_rt::distance_path_reply_t>(b.q.request_id);
      error = r.error, status = r.status;
    } else {
      const auto r = replies.wait_for<octomap_rt::distance_points_reply_t>(b.q.request_id);
      error = r.error, status = r.status;
    }
    EXPECT_EQ(status, Reply::REPLY_BAD_REQUEST) << b.q.request_id;
    EXPECT_NE(error.find(b.says), std::string::npos) << b.q.request_id << ": " << error;
  }
  // Bytes that are no distance_query_t: dropped before decode (nobody to answer), counted.
  const uint8_t junk[] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  lc.publish(protocol::kQueryDistanceChannel, junk, sizeof junk);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  server.stop();
  int64_t answered = 0, refused = 0, dropped = 0;
  for (const auto& c : server.query_stats()) {
    if (c.client_id == "tester") answered = c.answered, refused = c.bad;
    if (c.client_id == "?") dropped = c.dropped;
  }
  EXPECT_EQ(answered, 6);
  EXPECT_EQ(refused, int64_t(bad.size()));
  EXPECT_GE(dropped, 1);
}

TEST(DistanceQueries, TheVulkanEdtAnswersTheSame) {
  try {
    gpu::DistanceTransform probe;
  } catch (const Unsupported& e) {
    GTEST_SKIP() << "no Vulkan device: " << e.what();
  }
  lcm::LCM lc("memq://");
  daemon::ServerConfig cfg = test_config(0.1, true);
  cfg.queries.distance.backend = "vulkan";
  daemon::MappingServer server(cfg, lc, std::cerr);
  Replies replies(server);
  server.start();
  run_queries(server, lc, replies);
  server.stop();
}

}  // namespace
}  // namespace ort::test

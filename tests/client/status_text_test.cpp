// `octomap-rt status` layout and JSON of a known status message.
#include <gtest/gtest.h>

#include "cli/status/status_json.h"
#include "cli/status/status_text.h"

namespace ort::status {
namespace {

octomap_rt::server_status_t example_status() {
  octomap_rt::server_status_t s{};
  s.utime = 1'700'000'010'000'000;
  s.seq = 42;
  s.uptime_s = 3725;
  s.pid = 4242;
  s.state = octomap_rt::server_status_t::STATE_DEGRADED;
  s.pipelined = true;
  s.resolution = 0.1;
  s.num_nodes = 400844;
  s.memory_bytes = 10 * 1024 * 1024;
  s.scans_per_s = 12.5f;
  s.points_per_s = 1.5e6f;
  s.shoot_ms_p50 = 4.25f;
  s.end_to_end_ms_p99 = 30.5f;
  s.kernel_rcvbuf_errors = -1;
  s.last_save_utime = s.utime - 12'000'000;
  s.server_id = "srv-1";
  s.host = "robot-base";
  s.backend = "vulkan";
  s.device = "NVIDIA H100";
  s.message = "1 scan rejected in the last period";
  octomap_rt::robot_stats_t r{};
  r.robot_id = "alpha";
  r.channel = "OCTOMAP_RT_SCAN_ALPHA";
  r.scans_received = 1235;
  r.scans_applied = 1230;
  r.scans_rejected = 5;
  r.last_seq = 1234;
  r.last_scan_utime = s.utime - 500'000;
  r.reject_reason = {"non-finite pose", "truncated \"x\""};
  r.reject_count = {3, 2};
  r.num_reject_reasons = 2;
  r.point_drop_reason = {"non-finite", "below min range"};
  r.point_drop_count = {12000, 7};
  r.num_point_drop_reasons = 2;
  r.points_read_as_zero = 1500;
  s.robots = {r};
  s.num_robots = 1;
  return s;
}

TEST(StatusText, LaysOutStateRatesLatenciesAndRobotsWithReasons) {
  const auto s = example_status();
  const std::string text = format_status(s, s.utime + 2'000'000);
  EXPECT_NE(text.find("srv-1 (pid 4242 on robot-base)   state DEGRADED"), std::string::npos) << text;
  EXPECT_NE(text.find("up 1:02:05"), std::string::npos) << text;
  EXPECT_NE(text.find("status #42, 2 s ago"), std::string::npos) << text;
  EXPECT_NE(text.find("vulkan on NVIDIA H100, pipelined"), std::string::npos) << text;
  EXPECT_NE(text.find("400,844 nodes"), std::string::npos) << text;
  EXPECT_NE(text.find("10.0 MiB"), std::string::npos) << text;
  EXPECT_NE(text.find("points read as 0 (a coordinate below 1e-20 m): 1,500"), std::string::npos) << text;
  EXPECT_NE(text.find("last 14 s ago"), std::string::npos) << text;
  EXPECT_NE(text.find("12.5 scans/s, 1.50 M points/s"), std::string::npos) << text;
  EXPECT_NE(text.find("shoot 4.2 / 0.0"), std::string::npos) << text;
  EXPECT_NE(text.find("receive-buffer errors unknown"), std::string::npos) << text;
  EXPECT_NE(text.find("message   1 scan rejected"), std::string::npos) << text;
  EXPECT_NE(text.find("alpha            1,235     1,230"), std::string::npos) << text;
  EXPECT_NE(text.find("rejected: non-finite pose 3, truncated \"x\" 2"), std::string::npos) << text;
  EXPECT_NE(text.find("points without a ray: non-finite 12,000, below min range 7"), std::string::npos) << text;
}

octomap_rt::server_status_t with_queries() {
  auto s = example_status();
  s.queries_received = 1500, s.queries_answered = 1480, s.queries_bad = 2, s.queries_busy = 17;
  s.queries_not_ready = 1, s.queries_dropped = 3, s.edits_applied = 1, s.grids_published = 9;
  s.query_refusal_reason = {"depth # is not in #..#", "busy: the client's queue is full (--query-queue)"};
  s.query_refusal_count = {2, 17};
  s.num_query_refusal_reasons = 2;
  octomap_rt::query_client_stats_t c{};
  c.client_id = "planner1", c.reply_channel = "OCTOMAP_RT_REPLY_PLANNER1";
  c.received = 1500, c.answered = 1480, c.bad = 2, c.busy = 17, c.not_ready = 1, c.queue_depth = 3;
  c.last_utime = s.utime - 1'000'000, c.last_error = "depth 17 is not in 0..16";
  s.query_clients = {c};
  s.num_query_clients = 1;
  return s;
}

TEST(StatusText, ShowsQueryTotalsReasonsAndClients) {
  EXPECT_NE(format_status(example_status(), 0).find("queries   none yet"), std::string::npos);
  const auto s = with_queries();
  const std::string text = format_status(s, s.utime + 2'000'000);
  EXPECT_NE(text.find("queries   received 1,500: answered 1,480, bad 2, busy 17, not ready 1; dropped 3; edits 1 "
                      "applied, 0 refused; grids published 9"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("refused: depth # is not in #..# 2, busy: the client's queue is full (--query-queue) 17"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("planner1             1,500     1,480      2      17         1       0      3    3 s ago  "
                      "OCTOMAP_RT_REPLY_PLANNER1"),
            std::string::npos)
      << text;
}

TEST(StatusJson, CarriesTheQueryCounters) {
  const std::string json = status_json(with_queries());
  EXPECT_NE(json.find("\"queries\":{\"received\":1500,\"answered\":1480,\"bad\":2,\"busy\":17,\"not_ready\":1,"
                      "\"dropped\":3,\"edits_applied\":1,\"edits_refused\":0,\"grids_published\":9,"
                      "\"refusal_reasons\":{\"depth # is not in #..#\":2,"),
            std::string::npos)
      << json;
  EXPECT_NE(json.find("\"clients\":[{\"client_id\":\"planner1\",\"reply_channel\":\"OCTOMAP_RT_REPLY_PLANNER1\","
                      "\"received\":1500,\"answered\":1480,\"bad\":2,\"busy\":17,\"not_ready\":1,\"dropped\":0,"
                      "\"edits_applied\":0,\"edits_refused\":0,\"queue_depth\":3,"),
            std::string::npos)
      << json;
  EXPECT_NE(json.find("\"last_error\":\"depth 17 is not in 0..16\"}]}"), std::string::npos) << json;
}

octomap_rt::server_status_t serving() {
  auto s = example_status();
  s.map_version = 1236, s.latest_snapshot_id = 1230, s.snapshots_taken = 4, s.requests_served = 7;
  s.requests_rejected = 2, s.chunks_sent = 1350, s.deltas_sent = 412, s.last_delta_seq = 411;
  return s;
}

TEST(StatusText, ShowsTheServingCounters) {
  auto s = example_status();
  s.last_delta_seq = -1;
  const std::string none = format_status(s, 0);
  EXPECT_NE(none.find("serving   map version 0, latest snapshot none (0 taken); requests 0 served, 0 rejected\n"
                      "  sent      0 snapshot chunks, 0 deltas (none yet)\n"),
            std::string::npos)
      << none;
  const std::string text = format_status(serving(), 0);
  EXPECT_NE(text.find("serving   map version 1,236, latest snapshot #1,230 (4 taken); requests 7 served, 2 rejected\n"
                      "  sent      1,350 snapshot chunks, 412 deltas (last seq 411)\n"),
            std::string::npos)
      << text;
}

TEST(StatusJson, CarriesTheServingCounters) {
  const std::string json = status_json(serving());
  EXPECT_NE(json.find("\"map_version\":1236,\"latest_snapshot_id\":1230,\"snapshots_taken\":4,\"requests_served\":7,"
                      "\"requests_rejected\":2,\"chunks_sent\":1350,\"deltas_sent\":412,\"last_delta_seq\":411"),
            std::string::npos)
      << json;
}

TEST(StatusText, NumbersForPeople) {
  EXPECT_EQ(with_commas(0), "0");
  EXPECT_EQ(with_commas(999), "999");
  EXPECT_EQ(with_commas(1000), "1,000");
  EXPECT_EQ(with_commas(-1234567), "-1,234,567");
  EXPECT_EQ(bytes_text(512), "512 B");
  EXPECT_EQ(bytes_text(1536), "1.5 KiB");
  EXPECT_EQ(rate_text(4277.6), "4.3 k");
  EXPECT_EQ(rate_text(12.5), "12.5");
  EXPECT_EQ(duration_text(59), "59 s");
  EXPECT_EQ(duration_text(61), "1:01");
  EXPECT_EQ(duration_text(3600 * 26 + 1), "26:00:01");
  EXPECT_EQ(state_name(octomap_rt::server_status_t::STATE_RUNNING), "RUNNING");
  EXPECT_EQ(state_name(9), "STATE 9");
}

// A robot that restarted (seq back to 0) shows it: its seq gap is not lost scans.
TEST(StatusText, ShowsARobotsSeqRestarts) {
  auto s = example_status();
  s.robots[0].seq_restarts = 2;
  const std::string text = format_status(s, s.utime + 2'000'000);
  EXPECT_NE(text.find("seq restarts: 2"), std::string::npos) << text;
  EXPECT_EQ(format_status(example_status(), s.utime).find("seq restarts"), std::string::npos);
  EXPECT_NE(status_json(s).find("\"seq_restarts\":2"), std::string::npos) << status_json(s);
}

TEST(StatusText, ShowsWhyARobotsScansWereDropped) {
  auto s = example_status();
  s.robots[0].scans_dropped = 9;
  s.robots[0].drop_reason = {"queue full", "over latency bound"};
  s.robots[0].drop_count = {8, 1};
  s.robots[0].num_drop_reasons = 2;
  const std::string text = format_status(s, s.utime + 2'000'000);
  EXPECT_NE(text.find("    dropped: queue full 8, over latency bound 1\n"), std::string::npos) << text;
  EXPECT_EQ(format_status(example_status(), s.utime).find("dropped:"), std::string::npos);
  EXPECT_NE(status_json(s).find("\"drop_reasons\":{\"queue full\":8,\"over latency bound\":1}"), std::string::npos)
      << status_json(s);
}

TEST(StatusText, ShowsWhatTheMemoryBoundCosts) {
  auto s = example_status();
  EXPECT_EQ(format_status(s, s.utime).find("  bound "), std::string::npos) << "nothing without a bound";
  s.map_memory_bound = 8 << 20;
  s.resident_regions = 120;
  s.evicted_regions = 40;
  s.evicted_bytes = 3 << 20;
  s.region_evictions = 450;
  s.region_restores = 204;
  s.rss_bytes = 71 << 20;
  s.evict_passes = 61;
  s.evict_ms = 1450.5;
  s.evict_count_ms = 420;
  s.evict_ms_max = 148;
  s.restore_ms = 760.25;
  s.restore_ms_max = 107;
  const std::string text = format_status(s, s.utime);
  EXPECT_NE(text.find("  memory    bound 8.0 MiB: 10.0 MiB resident in 120 regions, 40 regions evicted (3.0 MiB in the "
                      "store); 450 evictions, 204 restores"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("  bound     61 passes 1450.5 ms (exact counts 420.0, longest 148.0); restores 760.2 ms (longest "
                      "107.0 a scan)\n"),
            std::string::npos)
      << text;
  const std::string json = status_json(s);
  for (const char* field :
       {"\"evict_passes\":61", "\"evict_ms\":1450.5", "\"evict_count_ms\":420", "\"evict_ms_max\":148",
        "\"restore_ms\":760.25", "\"restore_ms_max\":107", "\"evicted_bytes\":3145728", "\"map_memory_bound\":8388608"})
    EXPECT_NE(json.find(field), std::string::npos) << field << " in " << json;
}

TEST(StatusText, TheDistanceFieldCacheLineOnlyOnceItWorked) {
  octomap_rt::server_status_t s = example_status();
  EXPECT_EQ(format_status(s, s.utime).find("  distance  "), std::string::npos) << "no distance queries, no line";
  s.queries_received = 1300;  // the line is among the queries' (none: "none yet", no distance line)
  s.distance_fields_whole = 3, s.distance_fields_partial = 5, s.distance_fields_unchanged = 1200;
  s.distance_patched = 1190, s.distance_patch_changes = 43210, s.distance_reread = 18;
  s.distance_replies_kept = 1100, s.distance_frames = 240, s.distance_frames_kept = 97;
  const std::string text = format_status(s, s.utime);
  EXPECT_NE(text.find("  distance  fields 1,208: 3 whole, 5 partial, 1,200 unchanged (1,190 from change lists of "
                      "43,210 cells, 18 boxes read again); replies 1,100 resent, frames 97 of 240 kept\n"),
            std::string::npos)
      << text;
  const std::string json = status_json(s);
  for (const char* field :
       {"\"distance_fields_whole\":3", "\"distance_fields_partial\":5", "\"distance_fields_unchanged\":1200",
        "\"distance_patched\":1190", "\"distance_patch_changes\":43210", "\"distance_reread\":18",
        "\"distance_replies_kept\":1100", "\"distance_frames\":240", "\"distance_frames_kept\":97"})
    EXPECT_NE(json.find(field), std::string::npos) << field << " in " << json;
}

TEST(StatusJson, EveryFieldAndEscapedStrings) {
  const std::string json = status_json(example_status());
  EXPECT_EQ(json.front(), '{');
  EXPECT_EQ(json.back(), '}');
  EXPECT_NE(json.find("\"state_name\":\"DEGRADED\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"pid\":4242"), std::string::npos) << json;
  EXPECT_NE(json.find("\"pipelined\":true"), std::string::npos) << json;
  EXPECT_NE(json.find("\"reject_reasons\":{\"non-finite pose\":3,\"truncated \\\"x\\\"\":2}"), std::string::npos)
      << json;
  EXPECT_NE(json.find("\"point_drops\":{\"non-finite\":12000,\"below min range\":7}"), std::string::npos) << json;
  EXPECT_NE(json.find("\"points_read_as_zero\":1500"), std::string::npos) << json;
  EXPECT_EQ(json_string("a\nb\\"), "\"a\\u000ab\\\\\"");
}

}  // namespace
}  // namespace ort::status

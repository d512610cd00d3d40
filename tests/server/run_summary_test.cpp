// The run summary's list of the slowest scans: which scans are kept (daemon/slowest_scans.h)
// and what the summary says about each (daemon/run_summary.cpp).
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "core/clock.h"
#include "daemon/pipeline/slowest_scans.h"
#include "daemon/status/run_summary.h"

namespace ort::daemon {
namespace {

AppliedTiming timing(const SteadyClock::time_point start, double received_ms, double e2e_ms, int64_t seq) {
  AppliedTiming t;
  t.end_to_end_ms = e2e_ms;
  t.robot_id = "robot" + std::to_string(seq % 3);
  t.seq = seq;
  t.received = start + std::chrono::microseconds(static_cast<int64_t>(received_ms * 1000));
  return t;
}

TEST(SlowestScans, KeepsTheSlowestEndToEndSlowestFirstWithTheirPlaceInTheRun) {
  const auto start = SteadyClock::now();
  SlowestScans kept(3);
  const double e2e[] = {9.0, 2.0, 7.0, 1.0, 12.0, 7.5, 3.0, 8.0};
  for (int k = 0; k < 8; ++k) kept.add(timing(start, 10.0 * k, e2e[k], k));
  const auto& s = kept.slowest();
  ASSERT_EQ(s.size(), 3u);
  EXPECT_DOUBLE_EQ(s[0].timing.end_to_end_ms, 12.0);
  EXPECT_EQ(s[0].applied_index, 5);  // the 5th scan applied
  EXPECT_EQ(s[0].timing.seq, 4);
  EXPECT_NEAR(s[0].received_s, 0.040, 1e-9);
  EXPECT_DOUBLE_EQ(s[1].timing.end_to_end_ms, 9.0);
  EXPECT_EQ(s[1].applied_index, 1);
  EXPECT_NEAR(s[1].received_s, 0.0, 1e-9);
  EXPECT_DOUBLE_EQ(s[2].timing.end_to_end_ms, 8.0);
  EXPECT_EQ(s[2].applied_index, 8);
}

// Round robin in the shared class applies scans out of arrival order across producers: the
// times stay from the earliest receipt, never negative.
TEST(SlowestScans, ScansAppliedOutOfArrivalOrderCountFromTheEarliestReceipt) {
  const auto start = SteadyClock::now();
  SlowestScans kept(3);
  kept.add(timing(start, 30.0, 5.0, 1));  // arrived second, applied first
  kept.add(timing(start, 10.0, 4.0, 0));
  const auto s = kept.slowest();
  ASSERT_EQ(s.size(), 2u);
  EXPECT_NEAR(s[0].received_s, 0.020, 1e-9);
  EXPECT_NEAR(s[1].received_s, 0.0, 1e-9);
}

TEST(SlowestScans, FewerScansThanKeptAreAllListed) {
  const auto start = SteadyClock::now();
  SlowestScans kept(5);
  kept.add(timing(start, 0, 1.0, 0));
  kept.add(timing(start, 5, 3.0, 1));
  ASSERT_EQ(kept.slowest().size(), 2u);
  EXPECT_EQ(kept.slowest()[0].timing.seq, 1);
  EXPECT_EQ(kept.slowest()[1].timing.seq, 0);
  SlowestScans none(0);
  none.add(timing(start, 0, 1.0, 0));
  EXPECT_TRUE(none.slowest().empty());
}

TEST(SlowestScans, PipelineMetricsHandThemToTheSnapshot) {
  PipelineMetrics metrics;
  const auto start = SteadyClock::now();
  for (int k = 0; k < 7; ++k) metrics.record(timing(start, k, 1.0 + k, k));
  const MetricsSnapshot s = metrics.snapshot();
  ASSERT_EQ(s.slowest.size(), 5u);
  EXPECT_EQ(s.slowest.front().timing.seq, 6);
  EXPECT_EQ(s.slowest.back().timing.seq, 2);
}

TEST(RunSummary, ListsEachSlowScansPartsThatAddUpToItsEndToEndTime) {
  RunSummaryInputs in;
  SlowScan s;
  s.applied_index = 17;
  s.received_s = 0.123;
  AppliedTiming& t = s.timing;
  t.robot_id = "BENCH2";
  t.seq = 5;
  t.waits = {1.25, 2.5, 0.75};
  t.shoot_ms = 1.5;
  t.stage1.upload_ms = 0.25;
  t.stage1.prepare_ms = 0.5;
  t.stage1.shoot_ms = 0.5;
  t.stage1.compact_ms = 0.125;
  t.octree_ms = 4.0;
  t.stage2 = {0.5, 3.0, 0.25};
  t.end_to_end_ms = 10.0;
  t.voxels = 123456;
  t.new_nodes = 789;
  in.status.metrics.slowest = {s};
  in.status.metrics.scans_applied = 305;
  std::ostringstream out;
  print_run_summary(out, in);
  const std::string text = out.str();
  EXPECT_NE(text.find("slowest scans (end to end = decode + queue + stage 1 + hand-off + stage 2; of all 305 applied)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("#17 BENCH2 seq 5 at +0.123 s: 10.00 ms = decode 1.25 + queue 2.50 + stage 1 1.50 (upload 0.25, "
                      "prepare 0.50, shoot 0.50, compact 0.12) + hand-off 0.75 + stage 2 4.00 (lock wait 0.50, octree "
                      "3.00, deltas 0.25); 123456 voxels, 789 new nodes"),
            std::string::npos)
      << text;
}

TEST(RunSummary, NoScansNoSlowestList) {
  RunSummaryInputs in;
  std::ostringstream out;
  print_run_summary(out, in);
  EXPECT_EQ(out.str().find("slowest scans"), std::string::npos);
}

}  // namespace
}  // namespace ort::daemon

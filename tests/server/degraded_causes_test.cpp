// The rule behind DEGRADED: counters that grew since the last status period and trouble
// that lasts are causes; a quiet period after trouble clears them; the first kernel count
// is a baseline, not drops of the server's own.
#include "daemon/status/degraded_causes.h"

#include <gtest/gtest.h>

namespace ort::daemon {
namespace {

DegradedSignals quiet() {
  DegradedSignals s;
  s.queue_total_budget = 1000;
  s.kernel_drops = 0;
  return s;
}

TEST(DegradedCauses, AQuietServerIsNotDegraded) {
  DegradedTracker t;
  EXPECT_EQ(t.causes(quiet()), "");
  EXPECT_EQ(t.causes(quiet()), "");
}

TEST(DegradedCauses, DropsAndRejectionsCountOnlyInThePeriodTheyHappen) {
  DegradedTracker t;
  DegradedSignals s = quiet();
  EXPECT_EQ(t.causes(s), "");
  s.scans_dropped = 3;
  s.scans_rejected = 1;
  const std::string why = t.causes(s);
  EXPECT_NE(why.find("3 scans dropped"), std::string::npos) << why;
  EXPECT_NE(why.find("1 scans rejected"), std::string::npos) << why;
  EXPECT_EQ(t.causes(s), "") << "the same totals again: nothing new in this period";
  s.scans_dropped = 5;
  EXPECT_NE(t.causes(s).find("2 scans dropped"), std::string::npos);
}

TEST(DegradedCauses, TheFirstKernelCountIsABaseline) {
  DegradedTracker t;
  DegradedSignals s = quiet();
  s.kernel_drops = 1234;  // dropped before this server opened its socket
  EXPECT_EQ(t.causes(s), "");
  s.kernel_drops = 1240;
  EXPECT_NE(t.causes(s).find("6 UDP datagrams dropped by the kernel"), std::string::npos);
  s.kernel_drops = -1;  // unknown: never a cause
  EXPECT_EQ(t.causes(s), "");
}

TEST(DegradedCauses, LastingTroubleIsACauseInEveryPeriod) {
  DegradedTracker t;
  DegradedSignals s = quiet();
  s.save_error = "disk full";
  s.stuck_stage_s = 30;
  s.longest_busy_s = 31;
  s.queue_bytes = 950;
  s.latency_bound_s = 2;
  s.e2e_p99_ms = 2500;
  for (int period = 0; period < 2; ++period) {
    const std::string why = t.causes(s);
    EXPECT_NE(why.find("save failing (disk full)"), std::string::npos) << why;
    EXPECT_NE(why.find("stage stuck (31 s on one scan)"), std::string::npos) << why;
    EXPECT_NE(why.find("queue over its bound"), std::string::npos) << why;
    EXPECT_NE(why.find("latency over its bound"), std::string::npos) << why;
  }
}

TEST(DegradedCauses, BoundsAreNotCrossedAtOrBelowThem) {
  DegradedTracker t;
  DegradedSignals s = quiet();
  s.stuck_stage_s = 30;
  s.longest_busy_s = 30;
  s.queue_bytes = 900;  // exactly 90 % of the budget
  s.latency_bound_s = 2;
  s.oldest_queued_s = 2;
  s.e2e_p99_ms = 2000;
  EXPECT_EQ(t.causes(s), "");
  s.stuck_stage_s = 0;  // off: never stuck
  s.longest_busy_s = 1e6;
  s.latency_bound_s = 0;  // off
  s.oldest_queued_s = 1e6;
  s.e2e_p99_ms = 1e9;
  EXPECT_EQ(t.causes(s), "");
}

}  // namespace
}  // namespace ort::daemon

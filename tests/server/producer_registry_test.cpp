// Producer admission and seq accounting (issue 13, findings 8 and 10): seq arithmetic that
// cannot overflow (a jump is a restart, counted), idle producers let go so new robots can
// join after the channel slots ran out, and the --allow-robot list.
#include <climits>

#include <gtest/gtest.h>

#include "core/clock.h"
#include "daemon/intake/producer_registry.h"

namespace ort::daemon {
namespace {

bool admit(ProducerRegistry& r, size_t p, int64_t seq) {
  return r.admit(p, seq, 0, [] { return true; });
}

void apply_all(ProducerRegistry& r, size_t p, int n) {
  for (int i = 0; i < n; ++i) r.count_applied(p, 10, 1.0);
}

TEST(ProducerRegistry, SeqGapsAreCounted) {
  ProducerRegistry r("OCTOMAP_RT_SCAN_", 4);
  const size_t p = r.producer_for("OCTOMAP_RT_SCAN_A");
  for (int64_t seq : {0, 1, 5, 6}) admit(r, p, seq);
  EXPECT_EQ(r.snapshot()[p].missed, 3);
  EXPECT_EQ(r.snapshot()[p].seq_restarts, 0);
}

TEST(ProducerRegistry, HistoryIsValidScansSentOverTimeNotScansApplied) {
  // A share of the stages of its own (intake/scan_queue.h) comes with history; a flood that
  // keeps the shared class's scans from being applied must not keep a new robot from it.
  ProducerPolicy policy;
  policy.history_scans = 3;
  policy.history = std::chrono::duration<double>(0.05);
  ProducerRegistry r("OCTOMAP_RT_SCAN_", policy);
  const size_t p = r.producer_for("OCTOMAP_RT_SCAN_A");
  const auto t0 = SteadyClock::now();
  for (int64_t seq : {0, 1}) admit(r, p, seq);
  EXPECT_FALSE(r.has_history(p, t0 + std::chrono::seconds(1)));  // two scans: too few
  admit(r, p, 2);
  EXPECT_FALSE(r.has_history(p, SteadyClock::now()));           // three, but not over 50 ms yet
  EXPECT_TRUE(r.has_history(p, t0 + std::chrono::seconds(1)));  // none applied: still history
  r.count_rejected_arrival(p, Reject::kTruncated);
  const size_t q = r.producer_for("OCTOMAP_RT_SCAN_B");
  for (int k = 0; k < 3; ++k) r.count_rejected_arrival(q, Reject::kTruncated);
  EXPECT_FALSE(r.has_history(q, t0 + std::chrono::seconds(1)));  // invalid messages are no history
}

TEST(ProducerRegistry, ACopyOfTheLastScanIsRejectedNotAppliedTwice) {
  // The same message delivered or replayed twice (same seq, same utime) used to be queued
  // again, applied a second time and counted as a restart.
  ProducerRegistry r("OCTOMAP_RT_SCAN_", 4);
  const size_t p = r.producer_for("OCTOMAP_RT_SCAN_A");
  auto admit_at = [&](int64_t seq, int64_t utime) { return r.admit(p, seq, utime, [] { return true; }); };
  EXPECT_TRUE(admit_at(7, 1000));
  EXPECT_FALSE(admit_at(7, 1000));
  ProducerStats s = r.snapshot()[p];
  EXPECT_EQ(s.received, 2);
  EXPECT_EQ(s.rejected, 1);
  EXPECT_EQ(s.rejects[static_cast<size_t>(Reject::kDuplicateSeq)], 1);
  EXPECT_EQ(s.in_flight, 1);
  EXPECT_EQ(s.seq_restarts, 0);
  EXPECT_STREQ(to_string(Reject::kDuplicateSeq), "duplicate seq");
  // The same seq at another time is a restarted robot: queued, counted as a restart.
  EXPECT_TRUE(admit_at(7, 2000));
  EXPECT_TRUE(admit_at(8, 2100));
  s = r.snapshot()[p];
  EXPECT_EQ(s.seq_restarts, 1);
  EXPECT_EQ(s.rejected, 1);
  EXPECT_EQ(s.in_flight, 3);
}

TEST(ProducerRegistry, HugeSeqJumpIsARestartNotBillionsMissed) {
  // Finding 8: one scan with seq INT64_MAX used to leave scans_missed at 9.2e18 for good
  // (and INT64_MIN after INT64_MAX overflowed: UBSan).
  ProducerRegistry r("OCTOMAP_RT_SCAN_", 4);
  const size_t p = r.producer_for("OCTOMAP_RT_SCAN_A");
  for (int64_t seq : {int64_t{0}, int64_t{1}, INT64_MAX, INT64_MIN, int64_t{-500'000}, int64_t{2}, int64_t{3}})
    admit(r, p, seq);
  const ProducerStats s = r.snapshot()[p];
  EXPECT_EQ(s.missed, 0);
  EXPECT_EQ(s.seq_restarts, 4);  // 1 -> MAX (jump), MAX -> MIN (overflows), MIN -> -500000 (jump), -500000 -> 2 (jump)
  EXPECT_EQ(s.last_seq, 3);
  ProducerStats restart = s;
  // A plausible gap is still a gap; the bound is the policy's.
  admit(r, p, 3 + 1 + 100'000);
  EXPECT_EQ(r.snapshot()[p].missed, 100'000);
  admit(r, p, 3 + 1 + 100'000 + 100'002);
  EXPECT_EQ(r.snapshot()[p].missed, 100'000);
  EXPECT_EQ(r.snapshot()[p].seq_restarts, restart.seq_restarts + 1);
}

TEST(ProducerRegistry, IdleProducersAreLetGoSoNewRobotsCanJoin) {
  // Finding 10: after --max-producers channel names every new robot was rejected until restart.
  ProducerPolicy policy;
  policy.max_producers = 2;
  policy.idle_release = std::chrono::seconds(10);
  ProducerRegistry r("OCTOMAP_RT_SCAN_", policy);
  const auto t0 = SteadyClock::now();
  const size_t junk1 = r.producer_for("OCTOMAP_RT_SCAN_JUNK1", t0);
  const size_t junk2 = r.producer_for("OCTOMAP_RT_SCAN_JUNK2", t0);
  ASSERT_FALSE(r.is_overflow(junk1));
  ASSERT_FALSE(r.is_overflow(junk2));
  admit(r, junk1, 0);
  apply_all(r, junk1, 1);
  r.count_rejected_arrival(junk2, Reject::kBadRobotId);
  // Busy: a queued scan keeps junk2's slot even when old.
  admit(r, junk2, 0);

  const size_t early = r.producer_for("OCTOMAP_RT_SCAN_HUSKY1", t0 + std::chrono::seconds(5));
  EXPECT_TRUE(r.is_overflow(early));
  EXPECT_EQ(r.refusal(early), Reject::kTooManyProducers);
  r.count_rejected_arrival(early, r.refusal(early));

  const size_t later = r.producer_for("OCTOMAP_RT_SCAN_HUSKY1", t0 + std::chrono::seconds(11));
  ASSERT_FALSE(r.is_overflow(later));
  EXPECT_EQ(later, junk1) << "the idle slot (nothing in flight) is reused, not the busy one";
  EXPECT_EQ(r.expected_robot_id(later), "HUSKY1");
  EXPECT_TRUE(admit(r, later, 0));
  apply_all(r, later, 1);

  // junk2 still has a scan in flight and HUSKY1 is active: no slot for another newcomer.
  EXPECT_TRUE(r.is_overflow(r.producer_for("OCTOMAP_RT_SCAN_HUSKY2", t0 + std::chrono::seconds(15))));

  // The released producer's counts are kept (folded into one entry), so the sums balance.
  int64_t received = 0, settled = 0, released = 0;
  for (const ProducerStats& s : r.snapshot()) {
    received += s.received;
    settled += s.applied + s.rejected + s.dropped + s.in_flight;
    released += s.released;
  }
  EXPECT_EQ(received, settled);
  EXPECT_EQ(received, 5);
  EXPECT_EQ(released, 1);
}

TEST(ProducerRegistry, OnlyAllowedRobotsGetASlot) {
  ProducerPolicy policy;
  policy.max_producers = 1;
  policy.allowed_robots = {"husky1"};
  ProducerRegistry r("OCTOMAP_RT_SCAN_", policy);
  for (int i = 0; i < 5; ++i) {
    const size_t evil = r.producer_for("OCTOMAP_RT_SCAN_EVIL" + std::to_string(i));
    ASSERT_TRUE(r.is_overflow(evil));
    EXPECT_EQ(r.refusal(evil), Reject::kRobotNotAllowed);
    r.count_rejected_arrival(evil, r.refusal(evil));
  }
  const size_t husky = r.producer_for("OCTOMAP_RT_SCAN_HUSKY1");
  EXPECT_FALSE(r.is_overflow(husky)) << "refused channels must not use up the slots";
  EXPECT_EQ(r.refusal(husky), Reject::kNone);
}

}  // namespace
}  // namespace ort::daemon

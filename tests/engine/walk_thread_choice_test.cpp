// The cpu-grid walk's choice between the caller's thread alone and all its threads when it
// shares the cores with the octree stage (cpu/walk_thread_choice.h): helpers that get at
// least half a core keep walking, starved ones are let go, and measured again now and then.
#include <gtest/gtest.h>

#include "cpu/walk_thread_choice.h"

namespace ort {
namespace {

constexpr size_t kRays = WalkThreadChoice::kJudgedFrom;

TEST(WalkThreadChoice, AllThreadsUntilTheHelpersWereMeasured) {
  WalkThreadChoice c(4);
  EXPECT_EQ(c.next(), 4u);
  EXPECT_LT(c.helper_share(), 0.0);
  c.record(4, kRays - 1, 10.0, 0.0);  // too few rays to judge
  EXPECT_EQ(c.next(), 4u);
}

TEST(WalkThreadChoice, StarvedHelpersAreLetGoAndProbedEveryFewWindows) {
  WalkThreadChoice c(2);
  c.record(2, kRays, 10.0, 1.0);  // the helper got a tenth of a core
  EXPECT_DOUBLE_EQ(c.helper_share(), 0.1);
  int with_helpers = 0;
  for (unsigned w = 0; w < 4 * WalkThreadChoice::kProbeEvery; ++w) {
    const unsigned n = c.next();
    with_helpers += n > 1;
    c.record(n, kRays, 10.0, n > 1 ? 1.0 : 0.0);
  }
  EXPECT_EQ(with_helpers, 4);  // one probe in kProbeEvery windows
}

TEST(WalkThreadChoice, HelpersThatGetTheirCoresKeepWalking) {
  WalkThreadChoice c(3);
  c.record(3, kRays, 10.0, 2.0);  // two helpers, a tenth of a core each
  EXPECT_EQ(c.next(), 1u);
  for (unsigned w = 0; w + 1 < WalkThreadChoice::kProbeEvery; ++w) c.record(c.next(), kRays, 10.0, 0.0);
  ASSERT_EQ(c.next(), 3u);         // the probe
  c.record(3, kRays, 10.0, 19.0);  // now they got 0.95 of a core each: the other stage went idle
  EXPECT_NEAR(c.helper_share(), 0.95, 1e-12);
  for (int w = 0; w < 20; ++w) {
    ASSERT_EQ(c.next(), 3u);
    c.record(3, kRays, 10.0, 12.0);
  }
}

TEST(WalkThreadChoice, OneThreadIsAlwaysOne) {
  WalkThreadChoice c(1);
  EXPECT_EQ(c.next(), 1u);
  c.record(1, kRays, 10.0, 0.0);
  EXPECT_EQ(c.next(), 1u);
}

}  // namespace
}  // namespace ort

// Rays across shards (issue 26): on the real 3DTK scans, 3 hashed shards with small regions and
// 2 box shards each answer ray queries through the daemon's own answers on their own maps, each
// stopping in its own regions only; merged as the shard client merges them
// (client/shard_client/shard_rays.h), every ray's answer (hit, end point, end state) equals the
// one daemon's castRay on the whole map, stopping at unknown space or passing it, with and
// without a max range. The walk a shard takes is castRay's key for key (checked against castRay
// itself), and without the shards' rule the merge is wrong (checked, so the comparison can fail).
#include <gtest/gtest.h>

#include <optional>

#include "daemon/queries/query_answers.h"
#include "octomap_rt/ray_query_t.hpp"
#include "octomap_rt/ray_reply_t.hpp"
#include "query/ray_query.h"
#include "server/shard_maps.h"
#include "shard_client/shard_distance.h"
#include "shard_client/shard_rays.h"

namespace ort::test {
namespace {

using RQ = octomap_rt::ray_query_t;
using RR = octomap_rt::ray_reply_t;
constexpr double kRes = 0.2;

class ShardRays : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    map_ = sharded_3dtk(kRes);
    if (!map_) return;
    // From each scan's sensor: towards every 53rd end point, to 1.5 x past it. From points near
    // the surfaces (shifted off them, so some start in free, some in unknown space) in fixed
    // directions spread over the sphere.
    size_t n = 0;
    for (const PosedScan& s : map_->scans->scans) {
      const octomap::point3d o = sensor_origin(s);
      const octomap::Pointcloud w = world_points(s);
      for (size_t i = 0; i < w.size() && n < 700; i += 53, ++n) {
        const octomap::point3d d = (w[i] - o) * 1.5f;
        origins_.insert(origins_.end(), {o.x(), o.y(), o.z()});
        directions_.insert(directions_.end(), {d.x(), d.y(), d.z()});
        const float shift = 0.13f * float(n % 9) - 0.5f;
        origins_.insert(origins_.end(), {w[i].x() + shift, w[i].y() - 0.7f * shift, w[i].z() + 0.4f * shift});
        const float a = 2.39996f * float(n), z = 1.0f - 2.0f * float(n % 97) / 96.0f;
        directions_.insert(directions_.end(), {std::cos(a), std::sin(a), z});
      }
    }
  }
  static void TearDownTestSuite() { map_.reset(); }
  void SetUp() override {
    if (!map_) GTEST_SKIP() << "3dtk_3scans.graph not found";
  }

  static RQ query(bool ignore_unknown, float max_range) {
    RQ q{};
    q.ignore_unknown = ignore_unknown, q.max_range = max_range;
    q.origin_xyz = origins_, q.direction_xyz = directions_, q.num_xyz = int32_t(origins_.size());
    q.client_id = "planner", q.reply_channel = "R";
    return q;
  }
  // A daemon's reply to q from `tree` with shard set `shard`, as the query service computes it.
  static RR answer(const octomap::OcTree& tree, const RQ& q, const protocol::ShardSet& shard) {
    query::WorkBudget budget;
    const daemon::EncodedReplies r =
        daemon::answer_query(tree, daemon::QueryMessage{q}, daemon::MapStamp{1, 1, 1}, "test", {}, budget, shard);
    RR m;
    EXPECT_GE(m.decode(r.messages.at(0).data(), 0, int(r.messages.at(0).size())), 0);
    EXPECT_EQ(m.cut, 0) << m.error;
    return m;
  }
  // Rays whose answers differ between a and b.
  static int differing(const RR& a, const RR& b) {
    EXPECT_EQ(a.num_rays, b.num_rays);
    int n = 0;
    for (int j = 0; j < std::min(a.num_rays, b.num_rays); ++j)
      n += a.hit[j] != b.hit[j] || a.end_state[j] != b.end_state[j] || a.end_xyz[3 * j] != b.end_xyz[3 * j] ||
           a.end_xyz[3 * j + 1] != b.end_xyz[3 * j + 1] || a.end_xyz[3 * j + 2] != b.end_xyz[3 * j + 2];
    return n;
  }
  static RR merged(const ShardMaps& m, const RQ& q, bool with_rule) {
    std::vector<std::optional<RR>> got;
    for (size_t i = 0; i < m.sets.size(); ++i)
      got.push_back(answer(*m.trees[i], q, with_rule ? m.sets[i] : protocol::ShardSet{}));
    RR out;
    client::merge_shard_rays(out, got, origins_, m.sets[0], kRes);
    return out;
  }

  static inline std::unique_ptr<ShardedScans> map_;
  static inline std::vector<float> origins_, directions_;
};

TEST_F(ShardRays, MergedAnswersEqualTheOneDaemon) {
  for (const auto& [ignore_unknown, max_range] : {std::pair{false, -1.0f}, {false, 6.0f}, {true, 12.0f}}) {
    const RQ q = query(ignore_unknown, max_range);
    const RR want = answer(*map_->whole, q, {});
    int hits = 0, unknown_stops = 0;
    for (int j = 0; j < want.num_rays; ++j)
      hits += want.hit[j], unknown_stops += !want.hit[j] && want.end_state[j] == 0;
    const std::string what = std::string(ignore_unknown ? "ignoring unknown" : "stopping at unknown") + ", max range " +
                             std::to_string(max_range);
    // Both kinds of stop are common, so either rule's mistakes would show.
    EXPECT_GT(hits, want.num_rays / 5) << what;
    if (!ignore_unknown) {
      EXPECT_GT(unknown_stops, want.num_rays / 6) << what;
    }
    for (const ShardMaps& m : map_->sharded) {
      const RR got = merged(m, q, true);
      EXPECT_EQ(differing(got, want), 0) << m.what << ", " << what << ": of " << want.num_rays << " rays";
      // Rays that cross into another shard's regions before they stop: the merge matters for them.
      int crossing = 0;
      for (int j = 0; j < want.num_rays; ++j) {
        const float* o = &origins_[3 * j];
        const float* e = &want.end_xyz[3 * j];
        const auto owner = [&](const float* p) {
          int64_t k[3];
          for (int a = 0; a < 3; ++a)
            if (!client::voxel_key(p[a], kRes, k[a])) return m.sets[0].count;
          return protocol::shard_of(m.sets[0], protocol::region_coords(m.sets[0].region_depth, uint16_t(k[0]),
                                                                       uint16_t(k[1]), uint16_t(k[2])));
        };
        crossing += owner(o) != owner(e);
      }
      EXPECT_GT(crossing, want.num_rays / 20) << m.what << ", " << what;
    }
  }
}

// Without the rule (each shard casting as if it were the whole map) the merge stops at the
// first other shard's region a ray enters: most rays' answers are wrong.
TEST_F(ShardRays, WithoutTheShardRuleTheMergeIsWrong) {
  const RQ q = query(false, -1.0f);
  const RR want = answer(*map_->whole, q, {});
  EXPECT_GT(differing(merged(map_->sharded[0], q, false), want), want.num_rays / 4);
}

// The boxes rule asks only the shards a ray can reach (shards_for_rays): ray by ray, the merge of
// those shards' answers alone is still castRay's answer, and short rays often ask one shard only (0.6 m: 437 of 1,400).
TEST_F(ShardRays, BoxShardsNoRayReachesAreNotAsked) {
  const ShardMaps& m = map_->sharded[1];
  ASSERT_EQ(m.sets[0].rule, protocol::ShardRule::kBoxes);
  EXPECT_EQ(client::shards_for_rays(m.sets[0], origins_, directions_, -1.0f, kRes).size(), m.sets.size());
  for (const float max_range : {0.6f, 2.0f, 6.0f}) {
    const RQ q = query(false, max_range);
    const RR want = answer(*map_->whole, q, {});
    std::vector<RR> all;
    for (size_t i = 0; i < m.sets.size(); ++i) all.push_back(answer(*m.trees[i], q, m.sets[i]));
    int wrong = 0, alone = 0;
    for (int j = 0; j < want.num_rays; ++j) {
      const std::span<const float> o(&origins_[3 * j], 3), d(&directions_[3 * j], 3);
      const std::vector<uint32_t> asked = client::shards_for_rays(m.sets[0], o, d, max_range, kRes);
      alone += asked.size() == 1;
      std::vector<std::optional<RR>> got(m.sets.size());
      for (uint32_t i : asked) {  // ray j of shard i's answer, as a reply to that ray alone
        RR one;
        one.num_rays = 1, one.num_xyz = 3;
        one.hit = {all[i].hit[j]}, one.end_state = {all[i].end_state[j]};
        one.end_xyz.assign(&all[i].end_xyz[3 * j], &all[i].end_xyz[3 * j] + 3);
        got[i] = one;
      }
      RR out;
      client::merge_shard_rays(out, got, o, m.sets[0], kRes);
      wrong += out.num_rays != 1 || out.hit[0] != want.hit[j] || out.end_state[0] != want.end_state[j] ||
               out.end_xyz[0] != want.end_xyz[3 * j] || out.end_xyz[1] != want.end_xyz[3 * j + 1] ||
               out.end_xyz[2] != want.end_xyz[3 * j + 2];
    }
    EXPECT_EQ(wrong, 0) << m.what << ", max range " << max_range << ": of " << want.num_rays << " rays";
    if (max_range < 1) {
      EXPECT_GT(alone, want.num_rays / 5) << "max range " << max_range << ": " << alone << " of " << want.num_rays;
    }
  }
}

// A shard's walk is castRay's: with every voxel owned it answers castRay's answer on every ray.
TEST_F(ShardRays, TheOwnedWalkIsCastRay) {
  for (const bool ignore_unknown : {false, true})
    for (const double max_range : {-1.0, 0.7, 5.0, 30.0}) {
      if (ignore_unknown && max_range <= 0) continue;
      query::RayBatchOptions plain{ignore_unknown, max_range, {}}, owned = plain;
      owned.owns = [](const octomap::OcTreeKey&) { return true; };
      const auto a = query::cast_rays(*map_->whole, origins_, directions_, plain);
      const auto b = query::cast_rays(*map_->whole, origins_, directions_, owned);
      ASSERT_EQ(a.size(), b.size());
      int n = 0;
      for (size_t j = 0; j < a.size(); ++j) n += a[j].hit != b[j].hit || a[j].end != b[j].end;
      EXPECT_EQ(n, 0) << "ignore unknown " << ignore_unknown << ", max range " << max_range;
    }
}

}  // namespace
}  // namespace ort::test

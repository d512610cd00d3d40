// The distance field cache kept from the map's change lists (daemon/map/change_journal.h,
// daemon/queries/field_patch.h), through the daemon in one process over memq://: a robot maps
// new space scan after scan (the real 3DTK scans, each sent in parts so that every part adds
// obstacles and free space the box has not seen), and after every part a box, 1000 points
// inside it and a path answer exactly what a field computed whole from the map answers, while
// the cache took its grid from the change lists (its counters must say so, or a cache that
// read the map every time would pass); the same with cells of 2 voxels and unknown as
// occupied (cells read again from the tree); an edit between two queries (a state the journal
// does not list) makes the next box read the map again, and the answer is still exact.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "distance/distance_queries.h"
#include "distance/squared_edt.h"
#include "octomap_rt/distance_box_chunk_t.hpp"
#include "octomap_rt/distance_path_reply_t.hpp"
#include "octomap_rt/distance_points_reply_t.hpp"
#include "octomap_rt/distance_query_t.hpp"
#include "octomap_rt/map_edit_ack_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "octomap_rt/server_status_t.hpp"
#include "protocol/channels.h"
#include "protocol/limits.h"
#include "protocol/zstd_codec.h"
#include "server/query_test_support.h"
#include "server/scan_fixtures.h"
#include "support/test_data.h"

namespace ort::test {
namespace {

using DQ = octomap_rt::distance_query_t;
constexpr int kParts = 6;  // each 3DTK scan sent as this many scans (every kParts-th point)

// The 3DTK scans, each split into kParts scans of every kParts-th point, every 4th point kept.
std::vector<PosedScan> exploring_scans() {
  const ScanSet all = load_scan_graph(data_file("3dtk_dat/3dtk_3scans.graph"));
  std::vector<PosedScan> out;
  for (const PosedScan& s : all.scans)
    for (int part = 0; part < kParts; ++part) {
      PosedScan p = s;
      p.points.clear();
      for (size_t i = size_t(part) * 4; i < s.points.size(); i += size_t(kParts) * 4) p.points.push_back(s.points[i]);
      out.push_back(p);
    }
  return out;
}

// The box's squared distances, its chunks assembled and decompressed.
std::vector<uint32_t> box_field(Replies& replies, int64_t id, std::string& error) {
  const auto first = replies.wait_for<octomap_rt::distance_box_chunk_t>(id);
  error = first.error;
  if (first.status != Reply::REPLY_OK) return {};
  std::string blob(size_t(first.total_size), '\0');
  for (int32_t c = 0; c < first.num_chunks; ++c) {
    octomap_rt::distance_box_chunk_t m;
    bool found = false;
    for (int tries = 0; tries < 2000 && !found; ++tries) {
      {
        std::lock_guard lock(replies.m);
        for (const auto& b : replies.got)
          if (m.decode(b.data(), 0, int(b.size())) >= 0 && m.request_id == id && m.chunk_index == c) {
            found = true;
            break;
          }
      }
      if (!found) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    EXPECT_TRUE(found) << "chunk " << c << " of " << id;
    std::memcpy(blob.data() + size_t(c) * protocol::kChunkDataBytes, m.data.data(), m.data.size());
  }
  const std::string raw = protocol::zstd_decompress(blob, size_t(first.uncompressed_size));
  std::vector<uint32_t> sq(raw.size() / 4);
  std::memcpy(sq.data(), raw.data(), sq.size() * 4);
  return sq;
}

struct Explorer {
  QueryServer fixture{with_edits(test_config(0.1, true))};
  std::vector<PosedScan> scans = exploring_scans();
  double lo[3], hi[3];
  int64_t seq = 0, id = 0;

  Explorer() {
    // A 6 x 6 x 2.5 m box around the first scan's sensor: the scans after it map new space in it.
    const octomap::point3d o = scans[0].pose.trans();
    for (int a = 0; a < 3; ++a) lo[a] = o(a) - (a == 2 ? 1.0 : 3.0), hi[a] = o(a) + (a == 2 ? 1.5 : 3.0);
  }
  DQ query(int8_t mode, const distance::DistanceOptions& opt) {
    DQ q{};
    address(q, ++id);
    q.mode = mode, q.max_distance = opt.max_distance, q.cell_voxels = opt.cell_voxels;
    q.unknown_as = opt.unknown == distance::UnknownAs::kOccupied ? DQ::UNKNOWN_OCCUPIED : DQ::UNKNOWN_FREE;
    q.wait_robot_id = "rover", q.wait_seq = seq - 1, q.wait_timeout_ms = 20000;
    return q;
  }
  void send_scan(size_t k) {
    const auto msg = scan_message(scans[k % scans.size()], "rover", seq++);
    fixture.lc.publish("OCTOMAP_RT_SCAN_ROVER", &msg);
  }
  // A box query after the newest scan: equal to the field computed whole from the map.
  std::vector<uint32_t> last_box;
  int moved = 0;  // boxes whose answer differed from the one before
  void box_exact(const distance::DistanceOptions& opt) {
    DQ q = query(DQ::MODE_BOX, opt);
    std::copy(lo, lo + 3, q.box_min), std::copy(hi, hi + 3, q.box_max);
    fixture.lc.publish(protocol::kQueryDistanceChannel, &q);
    std::string error;
    const auto got = box_field(fixture.replies, q.request_id, error);
    EXPECT_EQ(error, "");
    const auto want = fixture.server.with_map([&](const octomap::OcTree& t) {
      return distance::answer_box(distance::read_box(t, lo, hi, opt, {}), distance::cpu_edt(1), false).squared;
    });
    EXPECT_EQ(got.size(), want.size());
    int64_t wrong = 0;
    for (size_t c = 0; c < std::min(got.size(), want.size()); ++c) wrong += got[c] != want[c];
    EXPECT_EQ(wrong, 0) << "request " << q.request_id;
    moved += !last_box.empty() && want != last_box;
    last_box = want;
  }
  void points_exact(const distance::DistanceOptions& opt, std::mt19937& rng) {
    DQ q = query(DQ::MODE_POINTS, opt);
    q.with_gradient = 1;
    for (int p = 0; p < 1000; ++p)
      for (int a = 0; a < 3; ++a) q.xyz.push_back(float(std::uniform_real_distribution<double>(lo[a], hi[a])(rng)));
    q.num_xyz = int32_t(q.xyz.size());
    fixture.lc.publish(protocol::kQueryDistanceChannel, &q);
    const auto r = fixture.replies.wait_for<octomap_rt::distance_points_reply_t>(q.request_id);
    ASSERT_EQ(r.status, Reply::REPLY_OK) << r.error;
    const auto want = fixture.server.with_map([&](const octomap::OcTree& t) {
      return distance::answer_points(distance::read_points(t, q.xyz, opt, {}), distance::cpu_edt(1));
    });
    ASSERT_EQ(r.distance.size(), want.size());
    int wrong = 0;
    for (size_t p = 0; p < want.size(); ++p)
      wrong += r.distance[p] != want[p].distance || r.gradient[3 * p] != want[p].gradient[0] ||
               r.gradient[3 * p + 1] != want[p].gradient[1] || r.gradient[3 * p + 2] != want[p].gradient[2];
    EXPECT_EQ(wrong, 0) << "request " << q.request_id;
  }
};

TEST(DistanceJournal, ARobotExploringGetsExactAnswersFromTheChangeLists) {
  Explorer e;
  distance::DistanceOptions opt;
  opt.max_distance = 0.85;
  std::mt19937 rng(27);
  for (size_t k = 0; k < e.scans.size(); ++k) {
    e.send_scan(k);
    e.box_exact(opt);
    if (k % 3 == 1) e.points_exact(opt, rng);
  }
  EXPECT_GE(e.moved, int(e.scans.size()) / 2) << "the parts must change the box's answer";
  const distance::FieldCacheStats s = e.fixture.server.distance_cache_stats();
  // The first box reads the map; every later box and every points query takes the change lists.
  EXPECT_GE(s.patched, int64_t(e.scans.size()) - 2 + int64_t(e.scans.size()) / 3 - 1);
  EXPECT_GE(s.partial + s.full, int64_t(e.scans.size()) - 2) << "each part must change the box's grid";
  // Every box made again is two z-slab frames (60 x 60 x 25 cells: slabs of 18 layers); the status says the same.
  EXPECT_GE(s.frames, 2 * (s.partial + s.full));
  EXPECT_LE(s.frames_kept, s.frames);
  const octomap_rt::server_status_t st = e.fixture.server.status();
  EXPECT_EQ(st.distance_fields_whole, s.full);
  EXPECT_EQ(st.distance_fields_partial, s.partial);
  EXPECT_EQ(st.distance_fields_unchanged, s.unchanged);
  EXPECT_EQ(st.distance_patched, s.patched);
  EXPECT_EQ(st.distance_patch_changes, s.patch_changes);
  EXPECT_EQ(st.distance_reread, s.reread);
  EXPECT_EQ(st.distance_replies_kept, s.replies_kept);
  EXPECT_EQ(st.distance_frames, s.frames);
  EXPECT_EQ(st.distance_frames_kept, s.frames_kept);
  ASSERT_TRUE(e.fixture.server.change_journal_stats().has_value());
  EXPECT_GE(e.fixture.server.change_journal_stats()->changes, 1000u);

  // An edit (not in the journal) between two queries: the next box reads the map again.
  octomap_rt::map_edit_t edit{};
  edit.request_id = ++e.id, edit.client_id = "op", edit.reply_channel = kReply;
  edit.op = octomap_rt::map_edit_t::OP_CLEAR_TO_FREE;
  for (int a = 0; a < 3; ++a) edit.box_min[a] = e.lo[a] + 1.0, edit.box_max[a] = e.lo[a] + 2.5;
  sign(edit);
  e.fixture.lc.publish(protocol::kMapEditChannel, &edit);
  ASSERT_EQ(e.fixture.replies.wait_for<octomap_rt::map_edit_ack_t>(edit.request_id).status, Reply::REPLY_OK);
  const int64_t reread = e.fixture.server.distance_cache_stats().reread;
  e.box_exact(opt);
  EXPECT_EQ(e.fixture.server.distance_cache_stats().reread, reread + 1);
}

TEST(DistanceJournal, CoarseCellsAndUnknownAsOccupiedReadTheirChangedCellsAgain) {
  Explorer e;
  distance::DistanceOptions opt;
  opt.max_distance = 1.05, opt.cell_voxels = 2, opt.unknown = distance::UnknownAs::kOccupied;
  for (size_t k = 0; k < 8; ++k) {
    e.send_scan(k);
    e.box_exact(opt);
  }
  EXPECT_GE(e.moved, 6);
  EXPECT_GE(e.fixture.server.distance_cache_stats().patched, 6);
}

}  // namespace
}  // namespace ort::test

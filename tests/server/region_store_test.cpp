// The memory bound's store on disk (daemon/persistence/region_store.h): regions of OctoMap's
// real FR-079 map put, read back whole, refused when damaged; the lock, the store's bound and
// a full disk; and a process killed (SIGKILL) while it spills regions loses none that a put
// had returned for, and leaves nothing half-written that a later open would take for a region.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "daemon/persistence/region_store.h"
#include "octree/region_codec.h"
#include "server/scan_fixtures.h"
#include "support/small_filesystem.h"
#include "support/test_data.h"

namespace ort::test {
namespace {

using daemon::RegionStore;
using daemon::RegionStoreError;

// The real map's regions at depth 12 that have a subtree, as bytes.
std::map<RegionId, std::vector<uint8_t>> real_regions(size_t most) {
  octomap::OcTree tree(0.08);
  EXPECT_TRUE(tree.readBinary(data_file("octomap_share/geb079.bt")));
  const RegionGrid grid = region_grid(12);
  std::map<RegionId, std::vector<uint8_t>> out;
  for (RegionId id : list_regions(tree, grid)) {
    const RegionNode r = find_region(tree, grid, id);
    if (r.depth != grid.depth || !tree.nodeHasChildren(r.node)) continue;
    out[id] = encode_region(tree, grid, id);
    if (out.size() == most) break;
  }
  return out;
}

RegionStoreError::Kind kind_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const RegionStoreError& e) {
    return e.kind();
  }
  ADD_FAILURE() << "no RegionStoreError";
  return RegionStoreError::Kind::kIo;
}

TEST(RegionStore, PutGetEraseLockBoundAndDamage) {
  const auto regions = real_regions(40);
  ASSERT_GT(regions.size(), 20u);
  const std::string dir = temp_dir("region-store") + "/map.ot.regions";
  {
    RegionStore store(dir, 1ull << 30);
    for (const auto& [id, b] : regions) store.put(id, b);
    EXPECT_EQ(store.ids().size(), regions.size());
    EXPECT_EQ(kind_of([&] { RegionStore second(dir, 1ull << 30); }), RegionStoreError::Kind::kLocked);
    for (const auto& [id, b] : regions) EXPECT_EQ(store.get(id), b);
    store.erase(regions.begin()->first);
    EXPECT_EQ(kind_of([&] { store.get(regions.begin()->first); }), RegionStoreError::Kind::kMissing);
  }
  {
    RegionStore store(dir, 1ull << 30);  // the lock went with the first store
    EXPECT_EQ(store.ids().size(), regions.size() - 1);
    // A damaged file is refused, not returned.
    const RegionId victim = std::next(regions.begin())->first;
    char name[40];
    std::snprintf(name, sizeof name, "/%012llx.region", (unsigned long long)victim);
    {
      std::fstream f(dir + name, std::ios::in | std::ios::out | std::ios::binary);
      f.seekp(40);
      f.put('\x7f');
    }
    EXPECT_EQ(kind_of([&] { store.get(victim); }), RegionStoreError::Kind::kCorrupt);
  }
  {
    // The store's own bound: a put past it writes nothing.
    const std::string small = temp_dir("region-store-bound");
    RegionStore store(small, regions.begin()->second.size() + 10);
    store.put(regions.begin()->first, regions.begin()->second);
    EXPECT_EQ(kind_of([&] { store.put(std::next(regions.begin())->first, std::next(regions.begin())->second); }),
              RegionStoreError::Kind::kFull);
    EXPECT_EQ(store.ids().size(), 1u);
  }
}

TEST(RegionStore, FullDiskRefusesThePutAndLeavesNothingHalfWritten) {
  const auto regions = real_regions(400);
  const std::string dir = temp_dir("region-store-full");
  const int rc = run_on_small_fs(dir, SmallFs{256 * 1024, false}, [&] {
    RegionStore store(dir + "/s", 1ull << 30);
    int full = 0;
    size_t stored = 0;
    for (const auto& [id, b] : regions) {
      try {
        store.put(id, b);
        ++stored;
      } catch (const RegionStoreError& e) {
        if (e.kind() != RegionStoreError::Kind::kFull) return 10;
        ++full;
      }
    }
    if (full == 0 || stored == 0) return 11;
    for (const auto& e : std::filesystem::directory_iterator(dir + "/s"))
      if (e.path().extension() == ".tmp") return 12;
    for (RegionId id : store.ids())
      if (store.get(id) != regions.at(id)) return 13;
    return 0;
  });
  if (rc == -1) GTEST_SKIP() << "no user/mount namespaces here";
  EXPECT_EQ(rc, 0);
}

TEST(RegionStore, KillDuringSpillLosesNothingThatWasPut) {
  const auto regions = real_regions(2000);
  ASSERT_GT(regions.size(), 200u);
  const std::string dir = temp_dir("region-store-kill") + "/map.ot.regions";
  int pipe_fd[2];
  ASSERT_EQ(::pipe(pipe_fd), 0);
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(pipe_fd[0]);
    RegionStore store(dir, 1ull << 30);
    for (int round = 0;; ++round)
      for (const auto& [id, b] : regions) {
        store.put(id, b);  // returned: durable
        const RegionId done = id;
        if (::write(pipe_fd[1], &done, sizeof done) != sizeof done) ::_exit(3);
      }
  }
  ::close(pipe_fd[1]);
  std::vector<RegionId> confirmed;
  RegionId id = 0;
  while (confirmed.size() < 150 && ::read(pipe_fd[0], &id, sizeof id) == sizeof id) confirmed.push_back(id);
  ::kill(child, SIGKILL);  // mid-put, most likely: puts follow each other without a pause
  int status = 0;
  ::waitpid(child, &status, 0);
  while (::read(pipe_fd[0], &id, sizeof id) == sizeof id) confirmed.push_back(id);  // sent before the kill
  ::close(pipe_fd[0]);
  ASSERT_TRUE(WIFSIGNALED(status));
  RegionStore store(dir, 1ull << 30);
  for (RegionId c : confirmed) EXPECT_EQ(store.get(c), regions.at(c)) << c;
  for (RegionId c : store.ids()) EXPECT_EQ(store.get(c), regions.at(c)) << "a region file that is not whole: " << c;
  for (const auto& e : std::filesystem::directory_iterator(dir)) EXPECT_NE(e.path().extension(), ".tmp");
}

}  // namespace
}  // namespace ort::test

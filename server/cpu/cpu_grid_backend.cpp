#include "cpu/cpu_grid_backend.h"

#include <sys/mman.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <limits>
#include <new>
#include <thread>
#include <vector>

#include "core/clock.h"
#include "core/exact_traversal.h"
#include "core/octomap_ray_walk.h"
#include "core/prepare_scan.h"
#include "core/ray_space.h"
#include "core/thread_priority.h"
#include "cpu/brick_layout.h"
#include "cpu/grid_marker.h"
#include "cpu/walk_thread_choice.h"
#include "cpu/window_walk_avx2.h"

namespace ort {
namespace {

constexpr uint32_t kVoxelsPerWord = BrickLayout::kVoxelsPerWord;
constexpr uint32_t kNoIndex = std::numeric_limits<uint32_t>::max();

// The persistent grid, in its own mapping: 2 MiB-aligned and marked for huge pages (a window
// of tens of MiB walked at random would otherwise miss the TLB on most line misses). Not from
// malloc: freed, a huge-page region would be handed to the process's small allocations
// (OctoMap's nodes), whose partial purges split and re-zero huge pages.
class GridMemory {
 public:
  static constexpr size_t kHugePage = 2u << 20;
  // One word more than asked: the AVX2 walk gathers 8 bytes at a word (walk_rays_avx2).
  explicit GridMemory(uint64_t words) : bytes_(((words + 1) * 4 + kHugePage - 1) / kHugePage * kHugePage) {
    mapped_bytes_ = bytes_ + kHugePage;
    mapped_ = mmap(nullptr, mapped_bytes_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mapped_ == MAP_FAILED) throw std::bad_alloc();
    const uintptr_t base = (reinterpret_cast<uintptr_t>(mapped_) + kHugePage - 1) / kHugePage * kHugePage;
    words_ = reinterpret_cast<uint32_t*>(base);
    madvise(words_, bytes_, MADV_HUGEPAGE);  // a hint: without it the grid still works
    // Not faulted in here: the kernel's pages come zeroed, each window uses the grid from its
    // start and leaves it zeroed, so only what the largest ray space so far needed is ever
    // resident (a small machine's scans need a few MiB of the budget; issue 25). The first
    // scan of each new size pays its page faults once (the daemon's warm-up scan takes them).
  }
  ~GridMemory() { munmap(mapped_, mapped_bytes_); }
  GridMemory(const GridMemory&) = delete;
  GridMemory& operator=(const GridMemory&) = delete;
  uint32_t* data() const { return words_; }

 private:
  size_t bytes_, mapped_bytes_;
  void* mapped_;
  uint32_t* words_;
};

// walk_octomap_ray_steps' stepper for a ray whose origin lies in the window: keeps the voxel
// index as the sum of per-axis offsets, and stops the walk where the ray leaves the window
// (each axis moves one way only, so a ray that left never comes back).
struct WindowStepper {
  WindowStepper(const BrickLayout& layout, const octomap::OcTreeKey& origin, const octomap::OcTreeKey& end,
                GridMarker& m)
      : marker(m),
        ox(layout.x_offsets()),
        oy(layout.y_offsets()),
        oz(layout.z_offsets()),
        x(origin[0] - layout.window().lo[0]),
        y(origin[1] - layout.window().lo[1]),
        z(origin[2] - layout.window().lo[2]),
        nx(layout.extent(0)),
        ny(layout.extent(1)),
        nz(layout.extent(2)),
        ix(ox[x]),
        iy(oy[y]),
        iz(oz[z]),
        end_index(layout.contains(end) ? layout.index(end) : kNoIndex) {}

  void start(int a, int b, int c) {
    sx = a, sy = b, sz = c;
    x_out = a > 0 ? nx : -1, y_out = b > 0 ? ny : -1, z_out = c > 0 ? nz : -1;
  }
  bool step_x() {
    x += sx;
    if (x == x_out) return false;
    ix = ox[x];
    return true;
  }
  bool step_y() {
    y += sy;
    if (y == y_out) return false;
    iy = oy[y];
    return true;
  }
  bool step_z() {
    z += sz;
    if (z == z_out) return false;
    iz = oz[z];
    return true;
  }
  bool at_end() const { return index() == end_index; }
  void visit() { marker.mark(index(), kStateFree); }
  uint32_t index() const { return ix + iy + iz; }

  GridMarker& marker;
  const uint32_t *ox, *oy, *oz;
  int x, y, z;  // key - window.lo
  int nx, ny, nz;
  uint32_t ix, iy, iz;
  uint32_t end_index;  // kNoIndex when the end voxel lies outside the window
  int sx = 0, sy = 0, sz = 0;
  int x_out = 0, y_out = 0, z_out = 0;  // the first coordinate outside the window along each step
};

class CpuGridBackend final : public RayBackend {
 public:
  explicit CpuGridBackend(const CpuGridOptions& o)
      : res_(o.resolution),
        threads_(o.threads ? o.threads : std::max(1u, std::thread::hardware_concurrency())),
        words_((o.grid_budget_bytes ? o.grid_budget_bytes : (256ull << 20)) / 4),
        simd_(o.simd && cpu_has_avx2()),
        helpers_yield_(o.helpers_yield),
        compact_alone_up_to_(o.compact_alone_up_to_words),
        choice_(threads_),
        grid_(words_) {}

  BackendKind kind() const override { return BackendKind::kCpuGrid; }
  std::string device_name() const override {
    return "CPU, " + std::to_string(threads_) + " threads (2-bit grid, " + std::to_string(words_ * 4 >> 20) + " MiB" +
           (simd_ ? ", AVX2 walk)" : ")");
  }

  void shoot(const RayBatch& batch, Traversal mode, VoxelList& out, ShootStats& stats) override {
    out.clear();
    stats.grid_words = words_;
    stats.grid_allocations = 1;
    const std::vector<KeyBox> windows = plan_bricked_windows(batch.keys);
    stats.windows += windows.size();
    const unsigned most = unsigned(std::min<size_t>(threads_, std::max<size_t>(1, batch.ends.size() / 256)));
    std::vector<std::vector<uint32_t>> touched(most);
    for (const KeyBox& w : windows) {
      const auto t_shoot = SteadyClock::now();
      const BrickLayout layout(w);
      const unsigned n_threads = helpers_yield_ ? std::min(most, choice_.next()) : most;
      const double helper_cpu_ms = walk_window(batch, mode, layout, n_threads, touched);
      const double walk_ms = ms_since(t_shoot);
      stats.times.shoot_ms += walk_ms;
      if (helpers_yield_) choice_.record(n_threads, batch.ends.size(), walk_ms, helper_cpu_ms);
      const auto t_compact = SteadyClock::now();
      compact_window(layout, n_threads, touched, out, stats);
      stats.times.compact_ms += ms_since(t_compact);
    }
  }

 private:
  template <class F>
  static void run_parallel(unsigned n, F&& f) {
    if (n == 1) return f(0u);
    std::vector<std::jthread> pool;
    pool.reserve(n - 1);
    for (unsigned t = 1; t < n; ++t) pool.emplace_back([&f, t] { f(t); });
    f(0u);
  }

  // plan_windows with room for the bricks' padding (and indices that fit 32 bits).
  std::vector<KeyBox> plan_bricked_windows(const KeyBox& keys) const {
    const uint64_t voxels = std::min<uint64_t>(words_ * kVoxelsPerWord, 1ull << 31);
    for (uint64_t capacity = voxels;; capacity -= std::max<uint64_t>(capacity / 8, 1)) {
      std::vector<KeyBox> windows = plan_windows(keys, capacity);
      if (std::all_of(windows.begin(), windows.end(),
                      [&](const KeyBox& w) { return BrickLayout::padded_voxels(w) <= voxels; }))
        return windows;
    }
  }

  void mark_checked(const BrickLayout& layout, const octomap::OcTreeKey& k, uint32_t bits, GridMarker& marker) {
    if (layout.contains(k)) marker.mark(layout.index(k), bits);
  }

  void shoot_ray(const RayBatch& b, const RayEnd& e, Traversal mode, const BrickLayout& layout, GridMarker& marker) {
    const octomap::point3d end(e.x, e.y, e.z);
    octomap::OcTreeKey end_key;
    coord_to_key_checked(end, res_, end_key);  // prepare_scan kept only in-range ends
    if (mode == Traversal::kExact) {
      thread_local std::vector<octomap::OcTreeKey> keys;
      keys.clear();
      exact_ray_keys(b.origin, end, res_, keys);
      for (const auto& k : keys) mark_checked(layout, k, kStateFree, marker);
    } else if (b.origin_key != end_key) {
      if (layout.contains(b.origin_key)) {
        walk_in_window(b, end, end_key, layout, marker);
      } else {  // a later window of a split ray space: the ray may enter it anywhere
        walk_octomap_ray(b.origin, end, b.origin_key, end_key, res_,
                         [&](const octomap::OcTreeKey& k) { mark_checked(layout, k, kStateFree, marker); });
      }
    }
    if (e.flags & kRayEndOccupied) mark_checked(layout, end_key, kStateOccupied, marker);
  }

  void walk_in_window(const RayBatch& b, const octomap::point3d& end, const octomap::OcTreeKey& end_key,
                      const BrickLayout& layout, GridMarker& marker) {
    WindowStepper s(layout, b.origin_key, end_key, marker);
    marker.mark(s.index(), kStateFree);
    walk_octomap_ray_steps(b.origin, end, b.origin_key, res_, s);
  }

  // Walks every ray of the batch into the window with n threads (touched[t] lists the words
  // thread t set first). Returns the CPU time the helper threads (all but the caller's) got.
  double walk_window(const RayBatch& batch, Traversal mode, const BrickLayout& layout, unsigned n_threads,
                     std::vector<std::vector<uint32_t>>& touched) {
    // Rays are taken in chunks from a shared counter, so a helper thread that gets little
    // CPU (helpers_yield) holds up the window by one chunk at most.
    std::atomic<size_t> next{0};
    std::atomic<int64_t> helper_cpu_ns{0};
    constexpr size_t kChunk = 1024;
    run_parallel(n_threads, [&](unsigned t) {
      if (t > 0 && helpers_yield_) lower_this_thread_priority(19);  // the lowest
      touched[t].clear();
      GridMarker marker{grid_.data(), touched[t], n_threads > 1};
      for (size_t begin; (begin = next.fetch_add(kChunk)) < batch.ends.size();) {
        const size_t end = std::min(batch.ends.size(), begin + kChunk);
        if (mode == Traversal::kOctomap && simd_ && layout.contains(batch.origin_key)) {
          walk_rays_avx2(batch, begin, end, layout, res_, marker);
        } else {
          for (size_t i = begin; i < end; ++i) shoot_ray(batch, batch.ends[i], mode, layout, marker);
        }
      }
      if (t > 0) helper_cpu_ns += thread_cpu_ns();  // a helper's thread starts with the window
    });
    return double(helper_cpu_ns.load()) * 1e-6;
  }

  // The walk's touched words into `out`. On the caller's thread unless the window touched
  // more than CpuGridOptions::compact_alone_up_to_words: measured on 2 cores, compacting a
  // window of a few ten thousand words took longer on two threads than on one (a thread
  // started per window, half of the words last written on the other core, a helper at the
  // lowest priority waited for).
  void compact_window(const BrickLayout& layout, unsigned n_threads, const std::vector<std::vector<uint32_t>>& touched,
                      VoxelList& out, ShootStats& stats) {
    size_t words = 0;
    for (unsigned t = 0; t < n_threads; ++t) words += touched[t].size();
    stats.words_touched += words;
    stats.words_read_back += words;
    if (n_threads == 1 || words <= compact_alone_up_to_) {
      for (unsigned t = 0; t < n_threads; ++t) compact(layout, touched[t], out);
      return;
    }
    std::vector<VoxelList> partial(n_threads);
    run_parallel(n_threads, [&](unsigned t) { compact(layout, touched[t], partial[t]); });
    for (unsigned t = 0; t < n_threads; ++t) out.insert(out.end(), partial[t].begin(), partial[t].end());
  }

  // Turns touched words into voxel updates (occupied wins) and clears them: the grid is
  // cleared through the touched list only, never by a pass over the window. Appends to `out`.
  void compact(const BrickLayout& layout, const std::vector<uint32_t>& touched, VoxelList& out) {
    uint32_t* grid = grid_.data();
    for (uint32_t word : touched) {
      uint32_t bits = grid[word];  // the walk's threads have joined: plain loads and stores
      grid[word] = 0;
      if (!bits) continue;
      const BrickLayout::WordKey first = layout.word_key(word);
      while (bits) {
        const int slot = __builtin_ctz(bits) / 2;
        const uint32_t state = (bits >> (2 * slot)) & 3u;
        bits &= ~(3u << (2 * slot));
        const octomap::OcTreeKey k = first.voxel(uint32_t(slot));
        out.push_back(VoxelUpdate{k[0], k[1], k[2], uint16_t((state & kStateOccupied) ? kStateOccupied : kStateFree)});
      }
    }
  }

  double res_;
  unsigned threads_;
  uint64_t words_;
  bool simd_;  // OctoMap walks in AVX2 lanes (window_walk_avx2.h) where the CPU has AVX2
  bool helpers_yield_;
  uint64_t compact_alone_up_to_;
  WalkThreadChoice choice_;  // used with helpers_yield_ only
  GridMemory grid_;
};

}  // namespace

std::unique_ptr<RayBackend> make_cpu_grid_backend(const CpuGridOptions& opts) {
  return std::make_unique<CpuGridBackend>(opts);
}

}  // namespace ort

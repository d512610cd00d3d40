#include "core/cpu_grid_backend.h"

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "core/clock.h"
#include "core/exact_traversal.h"
#include "core/octomap_ray_walk.h"
#include "core/prepare_scan.h"
#include "core/ray_space.h"

namespace ort {
namespace {

using Clock = std::chrono::steady_clock;

constexpr uint32_t kVoxelsPerWord = 16;

class CpuGridBackend final : public RayBackend {
 public:
  explicit CpuGridBackend(const CpuGridOptions& o)
      : res_(o.resolution),
        threads_(o.threads ? o.threads : std::max(1u, std::thread::hardware_concurrency())),
        words_((o.grid_budget_bytes ? o.grid_budget_bytes : (256ull << 20)) / 4),
        grid_(new std::atomic<uint32_t>[words_]) {
    for (uint64_t i = 0; i < words_; ++i) grid_[i].store(0, std::memory_order_relaxed);
  }

  BackendKind kind() const override { return BackendKind::kCpuGrid; }
  std::string device_name() const override {
    return "CPU, " + std::to_string(threads_) + " threads (2-bit grid, " + std::to_string(words_ * 4 >> 20) + " MiB)";
  }

  void shoot(const RayBatch& batch, Traversal mode, VoxelList& out, ShootStats& stats) override {
    out.clear();
    stats.grid_words = words_;
    stats.grid_allocations = 1;
    const std::vector<KeyBox> windows = plan_windows(batch.keys, words_ * kVoxelsPerWord);
    stats.windows += windows.size();
    const unsigned n_threads = unsigned(std::min<size_t>(threads_, std::max<size_t>(1, batch.ends.size() / 256)));
    std::vector<std::vector<uint32_t>> touched(n_threads);
    std::vector<VoxelList> partial(n_threads);
    for (const KeyBox& w : windows) {
      const auto t_shoot = Clock::now();
      run_parallel(n_threads, [&](unsigned t) {
        const size_t begin = batch.ends.size() * t / n_threads, end = batch.ends.size() * (t + 1) / n_threads;
        touched[t].clear();
        for (size_t i = begin; i < end; ++i) shoot_ray(batch, batch.ends[i], mode, w, touched[t]);
      });
      stats.times.shoot_ms += ms_since(t_shoot);
      const auto t_compact = Clock::now();
      run_parallel(n_threads, [&](unsigned t) {
        partial[t].clear();
        compact(w, touched[t], partial[t]);
      });
      for (unsigned t = 0; t < n_threads; ++t) {
        stats.words_touched += touched[t].size();
        stats.words_read_back += touched[t].size();
        out.insert(out.end(), partial[t].begin(), partial[t].end());
      }
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

  // Sets `bits` of voxel k if it lies in the window; lists the word when it was empty.
  [[gnu::always_inline]] void mark(const KeyBox& w, const octomap::OcTreeKey& k, uint32_t bits,
                                   std::vector<uint32_t>& touched) {
    const int64_t idx = window_index(w, k[0], k[1], k[2]);
    if (idx < 0) return;
    const uint64_t word = uint64_t(idx) / kVoxelsPerWord;
    const uint32_t mask = bits << (2 * (idx % kVoxelsPerWord));
    std::atomic<uint32_t>& cell = grid_[word];
    // Most visits near the sensor find their bit set already: read before the atomic.
    if ((cell.load(std::memory_order_relaxed) & mask) == mask) return;
    if (cell.fetch_or(mask, std::memory_order_relaxed) == 0) touched.push_back(uint32_t(word));
  }

  void shoot_ray(const RayBatch& b, const RayEnd& e, Traversal mode, const KeyBox& w, std::vector<uint32_t>& touched) {
    const octomap::point3d end(e.x, e.y, e.z);
    octomap::OcTreeKey end_key;
    coord_to_key_checked(end, res_, end_key);  // prepare_scan kept only in-range ends
    if (mode == Traversal::kOctomap) {
      walk_octomap_ray(b.origin, end, b.origin_key, end_key, res_,
                       [&](const octomap::OcTreeKey& k) { mark(w, k, kStateFree, touched); });
    } else {
      thread_local std::vector<octomap::OcTreeKey> keys;
      keys.clear();
      exact_ray_keys(b.origin, end, res_, keys);
      for (const auto& k : keys) mark(w, k, kStateFree, touched);
    }
    if (e.flags & kRayEndOccupied) mark(w, end_key, kStateOccupied, touched);
  }

  // Turns touched words into voxel updates (occupied wins) and clears them: the grid is
  // cleared through the touched list only, never by a pass over the window.
  void compact(const KeyBox& w, const std::vector<uint32_t>& touched, VoxelList& out) {
    const int64_t nx = w.hi[0] - w.lo[0] + 1, ny = w.hi[1] - w.lo[1] + 1;
    for (uint32_t word : touched) {
      uint32_t bits = grid_[word].exchange(0, std::memory_order_relaxed);
      while (bits) {
        const int slot = __builtin_ctz(bits) / 2;
        const uint32_t state = (bits >> (2 * slot)) & 3u;
        bits &= ~(3u << (2 * slot));
        const int64_t idx = int64_t(word) * kVoxelsPerWord + slot;
        const int x = int(idx % nx) + w.lo[0];
        const int y = int((idx / nx) % ny) + w.lo[1];
        const int z = int(idx / (nx * ny)) + w.lo[2];
        out.push_back(VoxelUpdate{uint16_t(x), uint16_t(y), uint16_t(z),
                                  uint16_t((state & kStateOccupied) ? kStateOccupied : kStateFree)});
      }
    }
  }

  double res_;
  unsigned threads_;
  uint64_t words_;
  std::unique_ptr<std::atomic<uint32_t>[]> grid_;
};

}  // namespace

std::unique_ptr<RayBackend> make_cpu_grid_backend(const CpuGridOptions& opts) {
  return std::make_unique<CpuGridBackend>(opts);
}

}  // namespace ort

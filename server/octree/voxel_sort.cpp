#include "octree/voxel_sort.h"

#include <algorithm>
#include <array>
#include <atomic>

namespace ort {
namespace {

constexpr unsigned kBucketBits = 11;     // first pass: 2048 buckets
constexpr size_t kParallelMin = 32768;   // below this the threads cost more than they save
constexpr size_t kInCacheVoxels = 8192;  // 64 KiB: LSD passes stay in L2

// Runs body(worker) on the pool's workers, or once on this thread without a pool.
template <class F>
void run_on(WorkerPool* pool, unsigned workers, F&& body) {
  if (workers <= 1 || !pool) {
    body(0u);
    return;
  }
  pool->run([&](unsigned w) {
    if (w < workers) body(w);
  });
}

// Bits in which some value differs from the first: the only ones the order depends on.
uint64_t varying_bits(const SortedVoxel* data, size_t n) {
  uint64_t acc = 0;
  for (size_t i = 0; i < n; ++i) acc |= data[i] ^ data[0];
  return acc;
}

// Sorts a range on its varying bits; `tmp` is as long as `data`; the result ends in
// `data`. Ranges that fit in cache, or have few varying bits, get LSD passes of 8 bits.
// Larger ones are first split on their own top 11 varying bits and each part sorted the
// same way: a scan crossing the map origin varies in every key bit (0x7fff -> 0x8000), so
// the top bits of the whole list only separate the 8 octants around the origin, and each
// octant has to be split again on the bits that vary inside it.
void sort_range(SortedVoxel* data, SortedVoxel* tmp, size_t n) {
  if (n < 64) {
    std::sort(data, data + n);
    return;
  }
  const uint64_t varying = varying_bits(data, n);
  if (varying == 0) return;
  const unsigned bits = 64u - static_cast<unsigned>(__builtin_clzll(varying));
  if (n > kInCacheVoxels && bits > 16) {
    const unsigned shift = bits - std::min(kBucketBits, bits);
    const uint64_t mask = (uint64_t{1} << (bits - shift)) - 1;
    std::vector<size_t> begin((mask + 2), 0);
    for (size_t i = 0; i < n; ++i) ++begin[((data[i] >> shift) & mask) + 1];
    for (size_t b = 1; b < begin.size(); ++b) begin[b] += begin[b - 1];
    std::vector<size_t> next(begin.begin(), begin.end() - 1);
    for (size_t i = 0; i < n; ++i) tmp[next[(data[i] >> shift) & mask]++] = data[i];
    std::copy(tmp, tmp + n, data);
    for (size_t b = 0; b + 1 < begin.size(); ++b)
      if (begin[b + 1] - begin[b] > 1) sort_range(data + begin[b], tmp + begin[b], begin[b + 1] - begin[b]);
    return;
  }
  SortedVoxel* src = data;
  SortedVoxel* dst = tmp;
  for (unsigned shift = 0; shift < bits; shift += 8) {
    std::array<size_t, 256> count{};
    for (size_t i = 0; i < n; ++i) ++count[(src[i] >> shift) & 0xffu];
    size_t offset = 0;
    for (size_t& c : count) {
      const size_t k = c;
      c = offset;
      offset += k;
    }
    for (size_t i = 0; i < n; ++i) dst[count[(src[i] >> shift) & 0xffu]++] = src[i];
    std::swap(src, dst);
  }
  if (src != data) std::copy(src, src + n, data);
}

}  // namespace

void sort_voxels(std::span<const VoxelUpdate> updates, std::vector<SortedVoxel>& out,
                 std::vector<SortedVoxel>& scratch, SortMethod method, WorkerPool* pool) {
  const size_t n = updates.size();
  out.resize(n);
  scratch.resize(n);
  if (n == 0) return;
  const unsigned workers = (pool && n >= kParallelMin) ? pool->size() : 1;
  auto chunk_begin = [&](unsigned w) { return n * w / workers; };

  // Codes into scratch, and which bits vary.
  const SortedVoxel first = make_sorted_voxel(updates[0]);
  std::vector<uint64_t> varying(workers, 0);
  run_on(pool, workers, [&](unsigned w) {
    uint64_t acc = 0;
    for (size_t i = chunk_begin(w), e = chunk_begin(w + 1); i < e; ++i) {
      scratch[i] = make_sorted_voxel(updates[i]);
      acc |= scratch[i] ^ first;
    }
    varying[w] = acc;
  });
  if (method == SortMethod::kStd) {
    std::sort(scratch.begin(), scratch.end());
    out.swap(scratch);
    return;
  }
  uint64_t all_varying = 0;
  for (uint64_t v : varying) all_varying |= v;
  if (all_varying == 0) {  // a single voxel
    out.swap(scratch);
    return;
  }

  // Most significant varying digit: scatter into buckets, each worker its own part of every
  // bucket, so the pass needs no locks and stays stable.
  const unsigned bits = 64u - static_cast<unsigned>(__builtin_clzll(all_varying));
  const unsigned bucket_bits = std::min(kBucketBits, bits);
  const unsigned shift = bits - bucket_bits;
  const size_t buckets = size_t{1} << bucket_bits;
  const uint64_t mask = buckets - 1;
  std::vector<size_t> offsets(workers * buckets, 0);  // [worker][bucket]
  run_on(pool, workers, [&](unsigned w) {
    size_t* count = &offsets[w * buckets];
    for (size_t i = chunk_begin(w), e = chunk_begin(w + 1); i < e; ++i) ++count[(scratch[i] >> shift) & mask];
  });
  std::vector<size_t> bucket_begin(buckets + 1);
  size_t offset = 0;
  for (size_t b = 0; b < buckets; ++b) {
    bucket_begin[b] = offset;
    for (unsigned w = 0; w < workers; ++w) {
      const size_t c = offsets[w * buckets + b];
      offsets[w * buckets + b] = offset;
      offset += c;
    }
  }
  bucket_begin[buckets] = n;
  run_on(pool, workers, [&](unsigned w) {
    size_t* next = &offsets[w * buckets];
    for (size_t i = chunk_begin(w), e = chunk_begin(w + 1); i < e; ++i) out[next[(scratch[i] >> shift) & mask]++] = scratch[i];
  });

  // Each bucket on its own (the bits above `shift` are equal inside one).
  std::atomic<size_t> next_bucket{0};
  run_on(pool, workers, [&](unsigned) {
    for (size_t b; (b = next_bucket.fetch_add(1, std::memory_order_relaxed)) < buckets;) {
      const size_t begin = bucket_begin[b], len = bucket_begin[b + 1] - begin;
      if (len > 1) sort_range(out.data() + begin, scratch.data() + begin, len);
    }
  });
}

}  // namespace ort

#include "octree/batched/voxel_buckets.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cstring>

namespace ort {
namespace {

constexpr size_t kParallelMin = 32768;  // below this the threads cost more than they save
constexpr size_t kAxisWords = 1024;     // 65536 bits: one per key coordinate
constexpr size_t kInsertionMax = 32;
constexpr unsigned kDirectMaxBits = 12;  // direct_sort: up to 4096 slots (32 KiB)

// A list is cut into chunks that the pool's threads take from a counter (WorkerPool::run_shared:
// a preempted thread's chunks go to the others). Passes 2 and 3 keep a row of per-cell counts
// per chunk, so their chunks are few: kChunksPerWorker per thread, of at least kMinChunk voxels.
constexpr size_t kChunksPerWorker = 3;
constexpr size_t kMinChunk = 4096;
constexpr size_t kMarkChunk = 8192;  // pass 1 keeps nothing per chunk

// Runs body(k) for every k in [0, count), shared out over the pool's threads, or here.
template <class F>
void for_each_chunk(WorkerPool* pool, size_t count, F&& body) {
  if (!pool || count <= 1) {
    for (size_t k = 0; k < count; ++k) body(k);
    return;
  }
  std::atomic<size_t> next{0};
  pool->run_shared([&](unsigned) {
    for (size_t k; (k = next.fetch_add(1, std::memory_order_relaxed)) < count;) body(k);
  });
}

// Sets bit v of `bits` unless it is set: most voxels repeat their neighbour's coordinates, so
// the threads mostly read the shared words and seldom take a cache line from each other.
inline void mark(uint64_t* bits, uint16_t v) {
  std::atomic_ref<uint64_t> word(bits[v >> 6]);
  const uint64_t bit = uint64_t{1} << (v & 63);
  if ((word.load(std::memory_order_relaxed) & bit) == 0) word.fetch_or(bit, std::memory_order_relaxed);
}

// Pass 1 on one thread: plain byte stores (consecutive voxels mostly repeat a coordinate, and
// read-modify-writes of one word would chain them), then the bytes packed into bits: about a
// quarter of mark()'s instructions a voxel, for a fixed 192 KiB to clear and pack a list.
void mark_alone(std::span<const VoxelUpdate> updates, std::vector<uint8_t>& seen, uint64_t* bits) {
  seen.assign(3 * 65536, 0);
  uint8_t* const set = seen.data();  // not through the vector: a byte store may alias its pointer
  for (const VoxelUpdate& u : updates) {
    set[u.x] = 1;
    set[65536 + u.y] = 1;
    set[2 * 65536 + u.z] = 1;
  }
  for (size_t word = 0; word < 3 * kAxisWords; ++word) {
    uint64_t packed = 0;
    for (unsigned k = 0; k < 8; ++k) {
      uint64_t bytes;  // eight 0/1 bytes
      std::memcpy(&bytes, set + word * 64 + k * 8, 8);
      // The multiplication moves byte j's bit to bit 56 + j, without carries.
      packed |= ((bytes * 0x0102040810204080ull) >> 56) << (k * 8);
    }
    bits[word] = packed;
  }
}

// Bit g * 2^shift of the result is set iff a bit of [g * 2^shift, (g + 1) * 2^shift) is
// (shift < 6: the groups lie inside the word).
uint64_t fold_groups(uint64_t v, unsigned shift) {
  static constexpr std::array<uint64_t, 6> kGroupStarts{~0ull,
                                                        0x5555555555555555ull,
                                                        0x1111111111111111ull,
                                                        0x0101010101010101ull,
                                                        0x0001000100010001ull,
                                                        0x0000000100000001ull};
  for (unsigned j = 0; j < shift; ++j) v |= v >> (1u << j);
  return v & kGroupStarts[shift];
}

// Whether a coordinate of node g at depth 16 - shift occurs (bits: one per key coordinate).
bool group_occupied(const uint64_t* bits, unsigned shift, size_t g) {
  if (shift >= 6) {
    const size_t words = size_t{1} << (shift - 6);
    uint64_t any = 0;
    for (size_t w = g * words; w < (g + 1) * words; ++w) any |= bits[w];
    return any != 0;
  }
  const size_t bit = g << shift;
  return ((fold_groups(bits[bit >> 6], shift) >> (bit & 63)) & 1u) != 0;
}

size_t occupied_groups(const uint64_t* bits, unsigned shift) {
  size_t n = 0;
  if (shift >= 6) {
    for (size_t g = 0; g < (size_t{1} << (16 - shift)); ++g) n += group_occupied(bits, shift, g);
    return n;
  }
  for (size_t w = 0; w < kAxisWords; ++w) n += static_cast<size_t>(std::popcount(fold_groups(bits[w], shift)));
  return n;
}

// Per axis: cell_of[v] = rank of node coordinate v among the occupied ones, times the
// axis's stride; node_of[rank] = v.
unsigned build_rank_table(const uint64_t* bits, unsigned shift, uint32_t stride, std::vector<uint32_t>& cell_of,
                          std::vector<uint16_t>& node_of) {
  const size_t nodes = size_t{1} << (16 - shift);
  cell_of.assign(nodes, 0);
  node_of.clear();
  auto add = [&](size_t g) {
    cell_of[g] = static_cast<uint32_t>(node_of.size()) * stride;
    node_of.push_back(static_cast<uint16_t>(g));
  };
  if (shift >= 6) {
    for (size_t g = 0; g < nodes; ++g)
      if (group_occupied(bits, shift, g)) add(g);
  } else {
    // A word at a time (this is serial work per scan): the occupied groups' first bits.
    for (size_t w = 0; w < kAxisWords; ++w)
      for (uint64_t f = fold_groups(bits[w], shift); f != 0; f &= f - 1)
        add((w * 64 + static_cast<size_t>(std::countr_zero(f))) >> shift);
  }
  return static_cast<unsigned>(node_of.size());
}

// A voxel's cell: the sum of its three coordinates' entries of the rank tables.
struct CellOf {
  const uint32_t *x, *y, *z;
  unsigned shift;
  uint32_t operator()(const VoxelUpdate& u) const { return x[u.x >> shift] + y[u.y >> shift] + z[u.z >> shift]; }
};

// Stable insertion sort on the code (bit 0, the state, is not part of the order).
void insertion_sort(SortedVoxel* v, size_t n) {
  for (size_t i = 1; i < n; ++i) {
    const SortedVoxel x = v[i];
    size_t j = i;
    for (; j > 0 && (v[j - 1] >> 1) > (x >> 1); --j) v[j] = v[j - 1];
    v[j] = x;
  }
}

// A bucket whose codes differ only in their low `bits` bits (a node of at most 4096 voxels,
// the usual bucket) and whose keys are all different (a scan's list has each key once): each
// voxel goes straight to the slot of its low bits, and the occupied slots are read back in
// order. Returns false, with `data` untouched, on a repeated key: the stable radix sort
// keeps the list's order of its updates.
bool direct_sort(SortedVoxel* data, size_t n, unsigned bits, std::vector<SortedVoxel>& tmp) {
  const size_t slots = size_t{1} << bits;
  const uint64_t mask = slots - 1;
  std::array<uint64_t, (size_t{1} << kDirectMaxBits) / 64> used;
  const size_t words = (slots + 63) / 64;
  std::fill_n(used.begin(), words, uint64_t{0});
  tmp.resize(std::max(tmp.size(), slots));
  for (size_t i = 0; i < n; ++i) {
    const uint64_t slot = (data[i] >> 1) & mask;
    const uint64_t bit = uint64_t{1} << (slot & 63);
    if (used[slot >> 6] & bit) return false;
    used[slot >> 6] |= bit;
    tmp[slot] = data[i];
  }
  size_t out = 0;
  for (size_t w = 0; w < words; ++w)
    for (uint64_t f = used[w]; f != 0; f &= f - 1) data[out++] = tmp[w * 64 + static_cast<size_t>(std::countr_zero(f))];
  return true;
}

}  // namespace

void bucket_voxels(std::span<const VoxelUpdate> updates, const BucketOptions& opts, WorkerPool* pool, VoxelBuckets& out,
                   BucketScratch& scratch) {
  const size_t n = updates.size();
  if (n > out.voxels.capacity()) {
    out.voxels = {};  // the last list is not kept: growing copies nothing, and a quarter spare
    out.voxels.reserve(n + n / 4);
  }
  out.voxels.resize(n);  // unwritten (UninitializedAllocator): the scatter pass writes them
  out.begin.clear();
  out.depth = 0;
  if (n == 0) return;
  if (pool && n < kParallelMin) pool = nullptr;
  const size_t chunks = pool ? std::clamp<size_t>(n / kMinChunk, 1, kChunksPerWorker * pool->size()) : 1;
  auto chunk_begin = [&](size_t k) { return n * k / chunks; };

  // Pass 1: which key coordinates occur, per axis, as bits shared by the threads.
  scratch.occupied.assign(3 * kAxisWords, 0);
  uint64_t* const axis_words = scratch.occupied.data();
  if (pool) {
    const size_t mark_chunks = (n + kMarkChunk - 1) / kMarkChunk;
    for_each_chunk(pool, mark_chunks, [&](size_t k) {
      const VoxelUpdate* u = updates.data();
      for (size_t i = n * k / mark_chunks, e = n * (k + 1) / mark_chunks; i < e; ++i) {
        mark(axis_words, u[i].x);
        mark(axis_words + kAxisWords, u[i].y);
        mark(axis_words + 2 * kAxisWords, u[i].z);
      }
    });
  } else {
    mark_alone(updates, scratch.seen, axis_words);
  }
  const uint64_t* axis_bits[3] = {axis_words, axis_words + kAxisWords, axis_words + 2 * kAxisWords};

  // The deepest depth whose cells fit the budget.
  const size_t budget = std::min(opts.max_cells, std::max<size_t>(64, n / std::max(1u, opts.voxels_per_cell)));
  unsigned shift = std::clamp(opts.min_shift, 1u, 15u);
  for (; shift < 15; ++shift) {
    size_t cells = 1;
    for (const uint64_t* bits : axis_bits) cells *= occupied_groups(bits, shift);
    if (cells <= budget) break;
  }
  out.depth = kTreeDepth - shift;
  std::array<std::vector<uint16_t>, 3> node_of;
  const unsigned nx = build_rank_table(axis_bits[0], shift, 1, scratch.cell_of_axis[0], node_of[0]);
  const unsigned ny = build_rank_table(axis_bits[1], shift, nx, scratch.cell_of_axis[1], node_of[1]);
  const unsigned nz = build_rank_table(axis_bits[2], shift, nx * ny, scratch.cell_of_axis[2], node_of[2]);
  const size_t cells = size_t{nx} * ny * nz;
  const CellOf cell_of{scratch.cell_of_axis[0].data(), scratch.cell_of_axis[1].data(), scratch.cell_of_axis[2].data(),
                       shift};

  // Pass 2: voxels per cell, per chunk (each chunk's row cleared by its thread first).
  scratch.counts.resize(chunks * cells);
  for_each_chunk(pool, chunks, [&, cell_of](size_t k) {
    uint32_t* count = &scratch.counts[k * cells];
    std::fill_n(count, cells, 0u);
    const VoxelUpdate* u = updates.data();
    if (chunk_begin(k) == chunk_begin(k + 1)) return;
    // Runs of voxels in one cell (a ray's) are counted in a register, not through memory.
    uint32_t cell = cell_of(u[chunk_begin(k)]), run = 0;
    for (size_t i = chunk_begin(k), e = chunk_begin(k + 1); i < e; ++i) {
      const uint32_t c = cell_of(u[i]);
      if (c != cell) {
        count[cell] += run;
        cell = c;
        run = 0;
      }
      ++run;
    }
    count[cell] += run;
  });

  // Per cell, on the threads (slices of cells): the cell's total, and each chunk's count
  // replaced by the sum of the chunks' before it, so that each chunk's part of a bucket comes
  // after the parts of the chunks before it (the buckets keep the list's order).
  scratch.totals.resize(cells);
  const size_t cell_slices = pool ? std::min<size_t>(chunks, (cells + 1023) / 1024) : 1;
  for_each_chunk(pool, cell_slices, [&](size_t slice) {
    for (size_t c = cells * slice / cell_slices, e = cells * (slice + 1) / cell_slices; c < e; ++c) {
      uint32_t sum = 0;
      for (size_t k = 0; k < chunks; ++k) {
        uint32_t& slot = scratch.counts[k * cells + c];
        const uint32_t n_here = slot;
        slot = sum;
        sum += n_here;
      }
      scratch.totals[c] = sum;
    }
  });

  // Occupied cells in Morton order of their nodes, and where each one's bucket begins.
  scratch.nonempty.clear();
  for (size_t c = 0; c < cells; ++c) {
    if (scratch.totals[c] == 0) continue;
    const size_t rx = c % nx, ry = c / nx % ny, rz = c / (size_t{nx} * ny);
    scratch.nonempty.emplace_back(morton_code(node_of[0][rx], node_of[1][ry], node_of[2][rz]),
                                  static_cast<uint32_t>(c));
  }
  std::sort(scratch.nonempty.begin(), scratch.nonempty.end());
  out.begin.reserve(scratch.nonempty.size() + 1);
  scratch.cell_begin.resize(cells);
  scratch.cell_code.resize(cells);
  size_t offset = 0;
  for (const auto& [code, c] : scratch.nonempty) {
    out.begin.push_back(offset);
    scratch.cell_begin[c] = static_cast<uint32_t>(offset);
    scratch.cell_code[c] = SortedVoxel{code} << (3 * shift + 1);
    offset += scratch.totals[c];
  }
  out.begin.push_back(n);

  // Pass 3: scatter. A voxel's code is its cell's node code (kept beside the cell's position,
  // like it changed only between runs) and the Morton code of its key's low `shift` bits: one
  // table lookup per axis where shift <= 8, not two.
  SortedVoxel* dst = out.voxels.data();
  const SortedVoxel* const cell_code = scratch.cell_code.data();
  const uint16_t low = static_cast<uint16_t>((1u << shift) - 1);
  auto scatter = [&, cell_of, dst, cell_code, low](size_t k, auto low_code) {
    uint32_t* next = &scratch.counts[k * cells];
    const VoxelUpdate* u = updates.data();
    if (chunk_begin(k) == chunk_begin(k + 1)) return;
    const uint32_t* cell_begin = scratch.cell_begin.data();
    for (size_t c = 0; c < cells; ++c) next[c] += cell_begin[c];  // only nonempty cells are read
    uint32_t cell = cell_of(u[chunk_begin(k)]), pos = next[cell];
    SortedVoxel code = cell_code[cell];
    for (size_t i = chunk_begin(k), e = chunk_begin(k + 1); i < e; ++i) {
      const uint32_t c = cell_of(u[i]);
      if (c != cell) {
        next[cell] = pos;
        cell = c;
        pos = next[c];
        code = cell_code[c];
      }
      dst[pos++] = code | (low_code(u[i].x & low, u[i].y & low, u[i].z & low) << 1) | (u[i].occupied() ? 1u : 0u);
    }
    next[cell] = pos;
  };
  if (shift <= 8) {
    for_each_chunk(pool, chunks, [&](size_t k) {
      scatter(k, [](uint16_t x, uint16_t y, uint16_t z) {
        return morton_code_low_byte(uint8_t(x), uint8_t(y), uint8_t(z));
      });
    });
  } else {
    for_each_chunk(pool, chunks, [&](size_t k) {
      scatter(k, [](uint16_t x, uint16_t y, uint16_t z) { return morton_code(x, y, z); });
    });
  }
}

void sort_bucket(std::span<SortedVoxel> bucket, std::vector<SortedVoxel>& tmp, unsigned node_bits) {
  const size_t n = bucket.size();
  SortedVoxel* data = bucket.data();
  if (n <= kInsertionMax) {
    insertion_sort(data, n);
    return;
  }
  // The usual bucket: a node of at most 4096 keys, each once (a repeated key goes on below).
  if (node_bits <= kDirectMaxBits && direct_sort(data, n, node_bits, tmp)) return;
  uint64_t varying = 0;
  for (size_t i = 0; i < n; ++i) varying |= data[i] ^ data[0];
  varying >>= 1;  // the code's bits
  if (varying == 0) return;
  const unsigned bits = 64u - static_cast<unsigned>(std::countl_zero(varying));
  if (bits <= kDirectMaxBits && direct_sort(data, n, bits, tmp)) return;
  // LSD radix passes of at most 8 bits over the varying code bits, all counted in one read.
  const unsigned passes = (bits + 7) / 8;
  const unsigned digit = (bits + passes - 1) / passes;
  const uint64_t mask = (uint64_t{1} << digit) - 1;
  std::array<std::array<uint32_t, 256>, 8> count;
  for (unsigned p = 0; p < passes; ++p) std::fill_n(count[p].begin(), mask + 1, 0u);
  for (size_t i = 0; i < n; ++i)
    for (unsigned p = 0; p < passes; ++p) ++count[p][(data[i] >> (1 + p * digit)) & mask];
  tmp.resize(std::max(tmp.size(), n));
  SortedVoxel* src = data;
  SortedVoxel* dst = tmp.data();
  for (unsigned p = 0; p < passes; ++p) {
    uint32_t offset = 0;
    for (uint64_t d = 0; d <= mask; ++d) {
      const uint32_t k = count[p][d];
      count[p][d] = offset;
      offset += k;
    }
    const unsigned shift = 1 + p * digit;
    for (size_t i = 0; i < n; ++i) dst[count[p][(src[i] >> shift) & mask]++] = src[i];
    std::swap(src, dst);
  }
  if (src != data) std::copy(src, src + n, data);
}

}  // namespace ort

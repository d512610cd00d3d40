// The cpu-grid's voxel layout inside one window: bricks of 8 x 8 x 4 voxels, one 64-byte
// cache line of 2-bit states, each brick 16 words of 8 x 2 x 1 voxels.
//
// Why: laid out x fastest, every y or z step of a ray's walk lands in another cache line
// (and, over a window of tens of MiB, often another page); in a brick a walk stays in one line
// for several steps. The index is a sum of one offset per axis (tables built once per window),
// so a walk keeps it incrementally: a step along x replaces only the x offset.
//
// A window small enough for one core's L2 (kRowsUpTo voxels) is laid out row by row instead (x
// fastest, each row whole words, words of 16 x 1 x 1): there the bricks' locality buys nothing,
// and the AVX2 walk keeps a row-by-row index with one add a step instead of the bricks' 16
// operations (docs/history/benchmarks-log.md, the cpu-grid walk's sections).
#pragma once

#include <cstdint>
#include <vector>

#include <octomap/OcTreeKey.h>

#include "core/ray_batch.h"

namespace ort {

class BrickLayout {
 public:
  static constexpr int kBrickX = 8, kBrickY = 8, kBrickZ = 4;
  static constexpr uint32_t kVoxelsPerBrick = kBrickX * kBrickY * kBrickZ;  // 256
  static constexpr uint32_t kVoxelsPerWord = 16;

  static constexpr uint64_t kRowsUpTo = 2u << 20;  // voxels: 512 KiB of 2-bit states

  // Row by row for window w by default (its rows' voxels at most kRowsUpTo), else bricks.
  static bool rows_for(const KeyBox& w) { return row_voxels(w) <= kRowsUpTo; }
  // Voxels the default layout of window w spans (w rounded up to whole bricks, or to rows of
  // whole words).
  static uint64_t padded_voxels(const KeyBox& w) { return rows_for(w) ? row_voxels(w) : brick_voxels(w); }

  explicit BrickLayout(const KeyBox& w, bool rows) : w_(w), rows_(rows), nbx_(bricks(w, 0)), nby_(bricks(w, 1)) {
    ox_.resize(size_t(w.hi[0] - w.lo[0] + 1));
    oy_.resize(size_t(w.hi[1] - w.lo[1] + 1));
    oz_.resize(size_t(w.hi[2] - w.lo[2] + 1));
    if (rows) {
      row_ = uint32_t(words_a_row(w) * kVoxelsPerWord), layer_ = row_ * uint32_t(oy_.size());
      for (uint32_t x = 0; x < ox_.size(); ++x) ox_[x] = x;
      for (uint32_t y = 0; y < oy_.size(); ++y) oy_[y] = y * row_;
      for (uint32_t z = 0; z < oz_.size(); ++z) oz_[z] = z * layer_;
      return;
    }
    row_ = brick_row(), layer_ = brick_layer();
    // Inside a brick: bits 0-2 x & 7, 3-5 y & 7, 6-7 z & 3 (a word is a row pair of 8 x 2 x 1).
    for (uint32_t x = 0; x < ox_.size(); ++x) ox_[x] = (x & 7u) | (x >> 3) * kVoxelsPerBrick;
    for (uint32_t y = 0; y < oy_.size(); ++y) oy_[y] = (y & 7u) << 3 | (y >> 3) * row_;
    for (uint32_t z = 0; z < oz_.size(); ++z) oz_[z] = (z & 3u) << 6 | (z >> 2) * layer_;
  }
  explicit BrickLayout(const KeyBox& w) : BrickLayout(w, rows_for(w)) {}

  bool rows() const { return rows_; }
  // Voxels this layout spans.
  uint64_t voxels() const { return rows_ ? uint64_t(layer_) * oz_.size() : brick_voxels(w_); }
  // Row by row: the index step of y + 1 and of z + 1 (bricks: brick_row() and brick_layer()).
  uint32_t y_stride() const { return row_; }
  uint32_t z_stride() const { return layer_; }

  const KeyBox& window() const { return w_; }
  // Per-axis offsets, indexed by key - window.lo.
  const uint32_t* x_offsets() const { return ox_.data(); }
  const uint32_t* y_offsets() const { return oy_.data(); }
  const uint32_t* z_offsets() const { return oz_.data(); }
  int extent(int axis) const { return w_.hi[axis] - w_.lo[axis] + 1; }
  // Voxels from one row of bricks (along x) to the next along y, and from one layer to the next along z:
  // the offsets above are these times y >> 3 and z >> 2, plus the voxel's place inside its brick.
  uint32_t brick_row() const { return kVoxelsPerBrick * nbx_; }
  uint32_t brick_layer() const { return brick_row() * nby_; }

  bool contains(const octomap::OcTreeKey& k) const {
    return k[0] >= w_.lo[0] && k[0] <= w_.hi[0] && k[1] >= w_.lo[1] && k[1] <= w_.hi[1] && k[2] >= w_.lo[2] &&
           k[2] <= w_.hi[2];
  }
  // Voxel index of a key inside the window (contains(k) must hold).
  uint32_t index(const octomap::OcTreeKey& k) const {
    return ox_[k[0] - w_.lo[0]] + oy_[k[1] - w_.lo[1]] + oz_[k[2] - w_.lo[2]];
  }
  // The key of slot `slot` (0-15) of word `word`.
  octomap::OcTreeKey key_of(uint32_t word, uint32_t slot) const { return word_key(word).voxel(slot); }

  // The key of a word's slot 0, from which its other slots follow by bit operations (the
  // brick's place takes divisions: once a word, not once a voxel).
  struct WordKey {
    int x, y, z;       // slot 0's key
    bool row = false;  // 16 x 1 x 1 (row by row), else 8 x 2 x 1
    octomap::OcTreeKey voxel(uint32_t slot) const {
      if (row) return octomap::OcTreeKey(octomap::key_type(x + int(slot)), octomap::key_type(y), octomap::key_type(z));
      return octomap::OcTreeKey(octomap::key_type(x + int(slot & 7u)), octomap::key_type(y + int(slot >> 3)),
                                octomap::key_type(z));
    }
  };
  WordKey word_key(uint32_t word) const {
    if (rows_) {
      const uint32_t voxel = word * kVoxelsPerWord, in_layer = voxel % layer_;
      return WordKey{int(in_layer % row_) + w_.lo[0], int(in_layer / row_) + w_.lo[1], int(voxel / layer_) + w_.lo[2],
                     true};
    }
    const uint32_t brick = word >> 4, in_brick = word & 15u;
    const uint32_t bx = brick % nbx_, by = (brick / nbx_) % nby_, bz = brick / (nbx_ * nby_);
    return WordKey{int(bx * kBrickX) + w_.lo[0], int(by * kBrickY + ((in_brick & 3u) << 1)) + w_.lo[1],
                   int(bz * kBrickZ + (in_brick >> 2)) + w_.lo[2]};
  }

 private:
  static uint64_t brick_voxels(const KeyBox& w) {
    return uint64_t(bricks(w, 0)) * bricks(w, 1) * bricks(w, 2) * kVoxelsPerBrick;
  }
  static uint64_t words_a_row(const KeyBox& w) {
    return (uint64_t(w.hi[0] - w.lo[0]) + kVoxelsPerWord) / kVoxelsPerWord;
  }
  static uint64_t row_voxels(const KeyBox& w) {
    return words_a_row(w) * kVoxelsPerWord * uint64_t(w.hi[1] - w.lo[1] + 1) * uint64_t(w.hi[2] - w.lo[2] + 1);
  }
  static uint32_t bricks(const KeyBox& w, int axis) {
    const int brick = axis == 0 ? kBrickX : axis == 1 ? kBrickY : kBrickZ;
    return uint32_t((w.hi[axis] - w.lo[axis] + brick) / brick);
  }

  KeyBox w_;
  bool rows_;
  uint32_t nbx_, nby_;
  uint32_t row_ = 0, layer_ = 0;  // the y and z strides (bricks: brick_row(), brick_layer())
  std::vector<uint32_t> ox_, oy_, oz_;
};

}  // namespace ort

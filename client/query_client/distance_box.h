// A dense distance box as a client holds it: the chunks of a distance_box_chunk_t reply
// assembled, checked (sizes, hash) and decompressed, with the distance and gradient of a
// cell read from it by the protocol's definitions (docs/PROTOCOL.md, "Distance queries").
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "octomap_rt/distance_box_chunk_t.hpp"

namespace ort::client {

class DistanceBoxError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct DistanceBox {
  octomap_rt::distance_box_chunk_t header;  // the first chunk, data cleared
  std::vector<uint32_t> squared;            // per cell, x fastest; 0xFFFFFFFF beyond max_distance
  std::vector<float> gradient;              // 3 per cell with the gradient, else empty

  int nx() const { return header.size[0]; }
  int ny() const { return header.size[1]; }
  int nz() const { return header.size[2]; }
  size_t index(int i, int j, int k) const { return (size_t(k) * ny() + j) * nx() + i; }
  // min(sqrt(squared) * cell_size, max_distance) [m].
  float distance(int i, int j, int k) const;
  std::array<double, 3> center(int i, int j, int k) const;
};

// From every chunk of one reply (any order). Throws DistanceBoxError when chunks are
// missing, sizes or the hash disagree, or the blob does not decompress to its cells.
DistanceBox assemble_distance_box(const std::vector<octomap_rt::distance_box_chunk_t>& chunks);

}  // namespace ort::client

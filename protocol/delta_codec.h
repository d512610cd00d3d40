// The payload of map_delta_t: sorted voxel keys as varint gaps, then one value per voxel
// (a class byte, or a float log-odds), zstd-compressed; cut into self-contained parts.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <octomap/OcTreeKey.h>

namespace ort::protocol {

// x << 32 | y << 16 | z: ascending order is x-major, and neighbouring voxels give small gaps.
inline uint64_t pack_key(const octomap::OcTreeKey& k) {
  return (static_cast<uint64_t>(k[0]) << 32) | (static_cast<uint64_t>(k[1]) << 16) | k[2];
}
inline octomap::OcTreeKey unpack_key(uint64_t p) {
  return octomap::OcTreeKey(static_cast<uint16_t>(p >> 32), static_cast<uint16_t>(p >> 16), static_cast<uint16_t>(p));
}

struct VoxelChange {
  uint64_t key = 0;  // pack_key
  float value = 0;   // MODE_CLASS: CLASS_FREE / CLASS_OCCUPIED; MODE_LOG_ODDS: log-odds
  bool operator==(const VoxelChange&) const = default;
};

struct DeltaPart {
  int32_t num_voxels = 0;
  int32_t uncompressed_size = 0;
  std::string data;  // compressed payload
};

// `sorted` ascending by key, keys unique. Each part's compressed payload is at most
// `max_bytes`. mode: map_delta_t::MODE_*.
std::vector<DeltaPart> encode_delta_parts(std::span<const VoxelChange> sorted, int8_t mode, int zstd_level,
                                          size_t max_bytes);

// Throws CodecError (zstd_codec.h) on any inconsistency: sizes, varints, key range or
// order, values that are not a class / not finite.
std::vector<VoxelChange> decode_delta_part(std::string_view data, int32_t num_voxels, int32_t uncompressed_size,
                                           int8_t mode);

}  // namespace ort::protocol

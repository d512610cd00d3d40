#include "protocol/delta_codec.h"

#include <cmath>
#include <cstring>

#include "octomap_rt/map_delta_t.hpp"
#include "protocol/zstd_codec.h"

namespace ort::protocol {
namespace {

using Delta = octomap_rt::map_delta_t;
constexpr int32_t kMaxVoxelsPerPart = 1 << 20;
constexpr uint64_t kKeyLimit = 1ull << 48;

size_t value_bytes(int8_t mode) { return mode == Delta::MODE_LOG_ODDS ? 4 : 1; }

void put_varint(std::string& out, uint64_t v) {
  while (v >= 0x80) {
    out += static_cast<char>((v & 0x7f) | 0x80);
    v >>= 7;
  }
  out += static_cast<char>(v);
}

std::string raw_payload(std::span<const VoxelChange> v, int8_t mode) {
  std::string out;
  out.reserve(v.size() * (4 + value_bytes(mode)));
  uint64_t prev = 0;
  for (const VoxelChange& c : v) {
    put_varint(out, c.key - prev);
    prev = c.key;
  }
  for (const VoxelChange& c : v) {
    if (mode == Delta::MODE_LOG_ODDS) {
      char b[4];
      std::memcpy(b, &c.value, 4);  // little-endian hosts only (x86-64, arm64)
      out.append(b, 4);
    } else {
      out += static_cast<char>(static_cast<int8_t>(c.value));
    }
  }
  return out;
}

}  // namespace

std::vector<DeltaPart> encode_delta_parts(std::span<const VoxelChange> sorted, int8_t mode, int zstd_level,
                                          size_t max_bytes) {
  std::vector<DeltaPart> parts;
  // First guess per part: what would fit uncompressed at 2x compression; halve until it fits.
  const size_t guess = std::max<size_t>(1, 2 * max_bytes / (3 + value_bytes(mode)));
  size_t i = 0;
  while (i < sorted.size()) {
    size_t n = std::min(guess, sorted.size() - i);
    for (;;) {
      const std::string raw = raw_payload(sorted.subspan(i, n), mode);
      std::string z = zstd_compress(raw, zstd_level);
      if (z.size() <= max_bytes || n == 1) {
        parts.push_back(DeltaPart{static_cast<int32_t>(n), static_cast<int32_t>(raw.size()), std::move(z)});
        break;
      }
      n = std::max<size_t>(1, n * max_bytes / z.size() * 9 / 10);
    }
    i += n;
  }
  return parts;
}

std::vector<VoxelChange> decode_delta_part(std::string_view data, int32_t num_voxels, int32_t uncompressed_size,
                                           int8_t mode) {
  if (mode != Delta::MODE_CLASS && mode != Delta::MODE_LOG_ODDS) throw CodecError("delta: unknown mode");
  if (num_voxels < 0 || num_voxels > kMaxVoxelsPerPart) throw CodecError("delta: voxel count out of range");
  const size_t vb = value_bytes(mode);
  const size_t max_raw = static_cast<size_t>(num_voxels) * (7 + vb);
  if (uncompressed_size < 0 || static_cast<size_t>(uncompressed_size) > max_raw)
    throw CodecError("delta: payload size does not fit the voxel count");
  const std::string raw = zstd_decompress(data, static_cast<size_t>(uncompressed_size));
  if (raw.size() != static_cast<size_t>(uncompressed_size)) throw CodecError("delta: payload size mismatch");
  std::vector<VoxelChange> out(static_cast<size_t>(num_voxels));
  size_t pos = 0;
  uint64_t key = 0;
  for (int32_t i = 0; i < num_voxels; ++i) {
    uint64_t gap = 0;
    for (int shift = 0;; shift += 7) {
      if (pos >= raw.size() || shift > 49) throw CodecError("delta: bad key varint");
      const auto b = static_cast<uint8_t>(raw[pos++]);
      gap |= static_cast<uint64_t>(b & 0x7f) << shift;
      if (!(b & 0x80)) break;
    }
    if (i > 0 && gap == 0) throw CodecError("delta: keys not strictly ascending");
    key += gap;
    if (key >= kKeyLimit) throw CodecError("delta: key out of range");
    out[i].key = key;
  }
  if (raw.size() - pos != static_cast<size_t>(num_voxels) * vb) throw CodecError("delta: value bytes mismatch");
  for (int32_t i = 0; i < num_voxels; ++i, pos += vb) {
    if (mode == Delta::MODE_LOG_ODDS) {
      float f;
      std::memcpy(&f, raw.data() + pos, 4);
      if (!std::isfinite(f)) throw CodecError("delta: non-finite log-odds");
      out[i].value = f;
    } else {
      const auto c = static_cast<int8_t>(raw[pos]);
      if (c != Delta::CLASS_FREE && c != Delta::CLASS_OCCUPIED) throw CodecError("delta: unknown class");
      out[i].value = c;
    }
  }
  return out;
}

}  // namespace ort::protocol

#include "protocol/scan_decode.h"

#include <cstring>
#include <vector>

#include "protocol/inbound_checks.h"

namespace ort::protocol {
namespace {

// Inner loops of a fixed trip count: vectorized at -O2 (GCC's cheap cost model takes only
// loops whose vector code replaces the scalar loop whole).
constexpr size_t kBlock = 16;

uint32_t be32(const uint8_t* p) {
  uint32_t w;
  std::memcpy(&w, p, 4);
  return __builtin_bswap32(w);
}

}  // namespace

void decode_be_floats(const uint8_t* src, float* dst, size_t count) {
  size_t i = 0;
  for (; i + kBlock <= count; i += kBlock) {
    for (size_t k = 0; k < kBlock; ++k) {
      const uint32_t w = be32(src + 4 * (i + k));
      std::memcpy(dst + i + k, &w, 4);
    }
  }
  for (; i < count; ++i) {
    const uint32_t w = be32(src + 4 * i);
    std::memcpy(dst + i, &w, 4);
  }
}

// LCM's decode runs on the message without its point array (num_xyz patched to 0), so every
// other field is decoded by the generated code as before; the array is decoded here.
int decode_scan(const uint8_t* data, size_t size, octomap_rt::scan_t& out) {
  if (size < kScanXyzOffset) return -1;
  const int32_t num_xyz = static_cast<int32_t>(be32(data + kScanNumXyzOffset));
  const size_t xyz_end = kScanXyzOffset + 4 * static_cast<size_t>(num_xyz);
  if (num_xyz < 0 || xyz_end > size) return -1;
  std::vector<uint8_t> rest;
  rest.reserve(size - (xyz_end - kScanXyzOffset));
  rest.insert(rest.end(), data, data + kScanXyzOffset);
  std::memset(rest.data() + kScanNumXyzOffset, 0, 4);
  rest.insert(rest.end(), data + xyz_end, data + size);
  out.xyz.clear();
  const int used = out.decode(rest.data(), 0, static_cast<int>(rest.size()));
  if (used < 0) return used;
  out.num_xyz = num_xyz;
  out.xyz.resize(static_cast<size_t>(num_xyz));
  decode_be_floats(data + kScanXyzOffset, out.xyz.data(), out.xyz.size());
  return used + static_cast<int>(xyz_end - kScanXyzOffset);
}

}  // namespace ort::protocol

#include "octree/batched/morton_order.h"

namespace ort {
namespace {

uint16_t compact_bits(uint64_t v) {
  v &= 0x249249249249ull;
  v = (v | (v >> 2)) & 0x0c30c30c30c3ull;
  v = (v | (v >> 4)) & 0x00f00f00f00full;
  v = (v | (v >> 8)) & 0x0000ff0000ffull;
  v = (v | (v >> 16)) & 0xffffu;
  return static_cast<uint16_t>(v);
}

}  // namespace

void morton_decode(uint64_t code, uint16_t& x, uint16_t& y, uint16_t& z) {
  x = compact_bits(code);
  y = compact_bits(code >> 1);
  z = compact_bits(code >> 2);
}

}  // namespace ort

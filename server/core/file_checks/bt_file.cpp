#include "core/file_checks/bt_file.h"

#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace ort {
namespace {

constexpr size_t kBtNodeBytes = 2;  // two bits a child (bit 2i the low one): 1 free leaf, 2 occupied leaf, 3 inner
constexpr size_t kOtNodeBytes = 5;  // a float log-odds and a byte of child bits

struct Converter {
  std::string_view data;
  float occupied, free;
  std::string& out;

  void put_node(size_t at, float value, uint8_t bits) {
    std::memcpy(out.data() + at, &value, sizeof value);
    out[at + 4] = static_cast<char>(bits);
  }

  size_t reserve_node() {
    out.resize(out.size() + kOtNodeBytes);
    return out.size() - kOtNodeBytes;
  }

  // Converts the inner node whose two bytes are at `at` (its own .ot node at `slot`); returns
  // where the data after its subtree starts, and in `any_occupied` whether a leaf under it is.
  size_t convert(size_t at, unsigned depth, size_t slot, bool& any_occupied) {
    if (at + kBtNodeBytes > data.size()) throw std::runtime_error("the map's node data ends inside a node");
    if (depth >= 16) throw std::runtime_error("the map has a node below the 16th level");
    const auto lo = static_cast<uint8_t>(data[at]), hi = static_cast<uint8_t>(data[at + 1]);
    at += kBtNodeBytes;
    uint8_t bits = 0;
    any_occupied = false;
    for (unsigned i = 0; i < 8; ++i) {
      const uint8_t pair = static_cast<uint8_t>(((i < 4 ? lo : hi) >> (2 * (i % 4))) & 3u);
      if (pair == 0) continue;
      bits = static_cast<uint8_t>(bits | (1u << i));
      const size_t child = reserve_node();
      if (pair == 3) {
        bool below = false;
        at = convert(at, depth + 1, child, below);
        any_occupied = any_occupied || below;
      } else {
        const bool occ = pair == 2;
        put_node(child, occ ? occupied : free, 0);
        any_occupied = any_occupied || occ;
      }
    }
    put_node(slot, any_occupied ? occupied : free, bits);
    return at;
  }
};

}  // namespace

std::string ot_file_from_bt(std::string_view bt, size_t data_offset, float occupied, float free) {
  if (data_offset > bt.size()) throw std::runtime_error("the map's header runs past its end");
  const std::string_view header = bt.substr(0, data_offset);
  const size_t first_line = header.find('\n');
  if (first_line == std::string_view::npos) throw std::runtime_error("the map's header has no lines");
  std::string out = "# Octomap OcTree file";
  out.append(header.substr(first_line));
  const size_t body_at = out.size();
  const std::string_view data = bt.substr(data_offset);
  if (data.empty()) return out;
  // A .ot node for every child pair set and the root: about 5/2 of the .bt's bytes and more.
  out.reserve(body_at + data.size() / kBtNodeBytes * 8 * kOtNodeBytes / 4);
  Converter c{data, occupied, free, out};
  const size_t root = c.reserve_node();
  bool any = false;
  if (c.convert(0, 0, root, any) != data.size()) throw std::runtime_error("the map's node data goes on past its tree");
  c.put_node(root, occupied, static_cast<uint8_t>(out[root + 4]));  // readBinary's root: the clamping maximum
  return out;
}

}  // namespace ort

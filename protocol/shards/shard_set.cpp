#include "protocol/shards/shard_set.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "protocol/channels.h"

namespace ort::protocol {
namespace {

std::string coords_text(uint32_t x, uint32_t y, uint32_t z) {
  return "(" + std::to_string(x) + ", " + std::to_string(y) + ", " + std::to_string(z) + ")";
}

std::string box_text(const RegionBox& b) {
  return coords_text(b.min[0], b.min[1], b.min[2]) + " .. " + coords_text(b.max[0], b.max[1], b.max[2]);
}

bool boxes_meet(const RegionBox& a, const RegionBox& b) {
  for (int k = 0; k < 3; ++k)
    if (std::max(a.min[k], b.min[k]) >= std::min(a.max[k], b.max[k])) return false;
  return true;
}

// A region in no box, found on the grid of the boxes' faces (each cell of that grid lies
// wholly inside or outside every box). Only called when the boxes' volumes fall short.
std::string find_gap(const std::vector<RegionBox>& boxes, uint32_t side) {
  std::vector<uint32_t> cuts[3];
  for (int k = 0; k < 3; ++k) {
    cuts[k] = {0, side};
    for (const RegionBox& b : boxes) cuts[k].insert(cuts[k].end(), {b.min[k], b.max[k]});
    std::sort(cuts[k].begin(), cuts[k].end());
    cuts[k].erase(std::unique(cuts[k].begin(), cuts[k].end()), cuts[k].end());
  }
  for (size_t i = 0; i + 1 < cuts[0].size(); ++i)
    for (size_t j = 0; j + 1 < cuts[1].size(); ++j)
      for (size_t k = 0; k + 1 < cuts[2].size(); ++k) {
        const RegionCoords r{cuts[0][i], cuts[1][j], cuts[2][k]};
        if (std::none_of(boxes.begin(), boxes.end(), [&](const RegionBox& b) { return b.contains(r); }))
          return coords_text(r.x, r.y, r.z);
      }
  return "?";
}

}  // namespace

uint32_t region_hash(const RegionCoords& r) {
  uint32_t h = (r.x * 73856093u) ^ (r.y * 19349663u) ^ (r.z * 83492791u);
  h ^= h >> 16;
  h *= 0x85ebca6bu;
  h ^= h >> 13;
  h *= 0xc2b2ae35u;
  h ^= h >> 16;
  return h;
}

uint32_t shard_of(const ShardSet& set, const RegionCoords& r) {
  switch (set.rule) {
    case ShardRule::kWhole: return 0;
    case ShardRule::kHash: return region_hash(r) % set.count;
    case ShardRule::kBoxes:
      for (uint32_t i = 0; i < set.boxes.size(); ++i)
        if (set.boxes[i].contains(r)) return i;
      return set.count;
  }
  return set.count;
}

std::string check_shard_set(const ShardSet& set) {
  if (set.count == 0 || set.count > kMaxShards)
    return "shard count " + std::to_string(set.count) + " is outside 1 .. " + std::to_string(kMaxShards);
  if (set.index >= set.count)
    return "shard index " + std::to_string(set.index) + " is not below the count " + std::to_string(set.count);
  if (set.region_depth < 1 || set.region_depth > 16)
    return "region depth " + std::to_string(set.region_depth) + " is outside 1 .. 16";
  if (set.rule == ShardRule::kWhole) return set.count == 1 ? "" : "a set of several shards needs a rule";
  if (set.rule == ShardRule::kHash) return set.boxes.empty() ? "" : "the hash rule takes no boxes";
  if (set.rule != ShardRule::kBoxes) return "unknown shard rule " + std::to_string(int(set.rule));
  if (set.boxes.size() != set.count)
    return std::to_string(set.boxes.size()) + " boxes for " + std::to_string(set.count) +
           " shards: give one --shard-box per shard, in shard order";
  const uint32_t side = 1u << set.region_depth;
  uint64_t volume = 0;
  for (size_t i = 0; i < set.boxes.size(); ++i) {
    const RegionBox& b = set.boxes[i];
    for (int k = 0; k < 3; ++k) {
      if (b.max[k] > side)
        return "box " + std::to_string(i) + " " + box_text(b) + " reaches past the key space (" + std::to_string(side) +
               " regions a side at depth " + std::to_string(set.region_depth) + ")";
      if (b.min[k] >= b.max[k]) return "box " + std::to_string(i) + " " + box_text(b) + " holds no region";
    }
    volume += uint64_t(b.max[0] - b.min[0]) * (b.max[1] - b.min[1]) * (b.max[2] - b.min[2]);
    for (size_t j = 0; j < i; ++j)
      if (boxes_meet(set.boxes[j], b)) {
        const RegionBox& a = set.boxes[j];
        return "boxes " + std::to_string(j) + " and " + std::to_string(i) + " overlap: region " +
               coords_text(std::max(a.min[0], b.min[0]), std::max(a.min[1], b.min[1]), std::max(a.min[2], b.min[2])) +
               " is in both";
      }
  }
  if (volume != uint64_t(side) * side * side)
    return "the boxes leave a gap: region " + find_gap(set.boxes, side) + " (depth " +
           std::to_string(set.region_depth) + ") is in no box; the boxes must cover the key space (use inf)";
  return "";
}

std::string parse_shard_index(std::string_view text, uint32_t& index, uint32_t& count) {
  const size_t slash = text.find('/');
  const std::string bad = "'" + std::string(text) + "' is not i/N (0 <= i < N <= " + std::to_string(kMaxShards) + ")";
  if (slash == std::string_view::npos) return bad;
  auto number = [](std::string_view s, uint32_t& v) {
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    return !s.empty() && r.ec == std::errc() && r.ptr == s.data() + s.size();
  };
  uint32_t i = 0, n = 0;
  if (!number(text.substr(0, slash), i) || !number(text.substr(slash + 1), n) || n == 0 || n > kMaxShards || i >= n)
    return bad;
  index = i, count = n;
  return "";
}

RegionBox region_box_of(const double min[3], const double max[3], double resolution, uint32_t depth) {
  const uint32_t side = 1u << depth, keys = 1u << (16 - depth);
  RegionBox b;
  for (int k = 0; k < 3; ++k) {
    // A region's min corner in metres: (its first key - 32768) * resolution (OctoMap's keys).
    auto corner = [&](uint32_t r) { return (double(r) * keys - 32768.0) * resolution; };
    uint32_t lo = 0, hi = 0;
    while (lo < side && !(corner(lo) >= min[k])) ++lo;
    hi = lo;
    while (hi < side && corner(hi) < max[k]) ++hi;
    b.min[k] = lo, b.max[k] = hi;
  }
  return b;
}

std::string shard_namespace(std::string_view ns, uint32_t index) {
  return in_namespace(ns, kShardNamespacePrefix + std::to_string(index));
}

const char* to_string(ShardRule rule) {
  switch (rule) {
    case ShardRule::kWhole: return "whole";
    case ShardRule::kHash: return "hash";
    case ShardRule::kBoxes: return "boxes";
  }
  return "?";
}

}  // namespace ort::protocol

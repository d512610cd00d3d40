#include "protocol/shards/shard_wire.h"

namespace ort::protocol {

const char* to_string(ShardFieldFault f) {
  switch (f) {
    case ShardFieldFault::kNone: return "";
    case ShardFieldFault::kUnknownRule: return "unknown shard rule";
    case ShardFieldFault::kBadDepth: return "shard region depth outside 1..16";
    case ShardFieldFault::kBadCount: return "bad shard count";
    case ShardFieldFault::kBadIndex: return "shard index not below the count";
    case ShardFieldFault::kBadBoxValues: return "bad shard box count";
    case ShardFieldFault::kBadBoxes: return "shard boxes do not tile the key space";
  }
  return "?";
}

ShardFieldFault read_shard_fields(const ShardFields& f, ShardSet& out) {
  ShardSet s;
  if (f.rule < 0 || f.rule > static_cast<int8_t>(ShardRule::kBoxes)) return ShardFieldFault::kUnknownRule;
  s.rule = static_cast<ShardRule>(f.rule);
  if (f.region_depth < 1 || f.region_depth > 16) return ShardFieldFault::kBadDepth;
  s.region_depth = static_cast<uint32_t>(f.region_depth);
  if (f.count < 1 || f.count > static_cast<int32_t>(kMaxShards) || (s.rule == ShardRule::kWhole && f.count != 1))
    return ShardFieldFault::kBadCount;
  s.count = static_cast<uint32_t>(f.count);
  if (f.index < 0 || f.index >= f.count) return ShardFieldFault::kBadIndex;
  s.index = static_cast<uint32_t>(f.index);
  const int64_t want = s.rule == ShardRule::kBoxes ? 6 * int64_t(s.count) : 0;
  if (f.num_box_values != want || (want > 0 && f.box_values == nullptr)) return ShardFieldFault::kBadBoxValues;
  for (int64_t b = 0; b < want / 6; ++b) {
    RegionBox box;
    for (int k = 0; k < 3; ++k) {
      const int32_t lo = f.box_values[6 * b + k], hi = f.box_values[6 * b + 3 + k];
      if (lo < 0 || hi < 0) return ShardFieldFault::kBadBoxes;
      box.min[k] = static_cast<uint32_t>(lo), box.max[k] = static_cast<uint32_t>(hi);
    }
    s.boxes.push_back(box);
  }
  if (!check_shard_set(s).empty()) return ShardFieldFault::kBadBoxes;
  out = std::move(s);
  return ShardFieldFault::kNone;
}

std::string describe(const ShardSet& s) {
  if (!s.sharded()) return "the whole map";
  return "shard " + std::to_string(s.index) + " of " + std::to_string(s.count) + " (" + to_string(s.rule) +
         ", regions at depth " + std::to_string(s.region_depth) + ")";
}

bool same_shard_set(const ShardSet& a, const ShardSet& b) {
  if (a.rule != b.rule || a.count != b.count || a.region_depth != b.region_depth || a.boxes.size() != b.boxes.size())
    return false;
  for (size_t i = 0; i < a.boxes.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (a.boxes[i].min[k] != b.boxes[i].min[k] || a.boxes[i].max[k] != b.boxes[i].max[k]) return false;
  return true;
}

}  // namespace ort::protocol

// The shard set on the wire: the shard_* fields that map_info_t and server_status_t carry
// alike (docs/PROTOCOL.md, "Shards"), written from a ShardSet and read back with every field
// range-checked, so a client that routes by them never trusts a number it did not check.
#pragma once

#include <cstdint>
#include <string>

#include "protocol/shards/shard_set.h"

namespace ort::protocol {

// Why a message's shard fields are not a shard set (kNone: they are); each has a short name.
enum class ShardFieldFault {
  kNone,
  kUnknownRule,   // shard_rule is no SHARD_RULE_*
  kBadDepth,      // shard_region_depth outside 1 .. 16
  kBadCount,      // shard_count outside 1 .. kMaxShards, or above 1 for the whole map
  kBadIndex,      // shard_index negative or not below shard_count
  kBadBoxValues,  // num_shard_box_values is not 6 per shard with boxes, 0 without
  kBadBoxes,      // the boxes do not tile the key space (check_shard_set)
};
const char* to_string(ShardFieldFault f);

template <class Msg>
void put_shard_set(const ShardSet& s, Msg& m) {
  m.shard_rule = static_cast<int8_t>(s.rule);
  m.shard_region_depth = static_cast<int8_t>(s.region_depth);
  m.shard_index = static_cast<int16_t>(s.index);
  m.shard_count = static_cast<int16_t>(s.count);
  m.shard_box.clear();
  if (s.rule == ShardRule::kBoxes)
    for (const RegionBox& b : s.boxes)
      for (const uint32_t* v : {b.min, b.max})
        for (int k = 0; k < 3; ++k) m.shard_box.push_back(static_cast<int32_t>(v[k]));
  m.num_shard_box_values = static_cast<int32_t>(m.shard_box.size());
}

// The fields as plain numbers, so one function checks both message types.
struct ShardFields {
  int8_t rule = 0, region_depth = 0;
  int16_t index = 0, count = 0;
  const int32_t* box_values = nullptr;
  int64_t num_box_values = 0;
};
ShardFieldFault read_shard_fields(const ShardFields& f, ShardSet& out);

template <class Msg>
ShardFieldFault read_shard_set(const Msg& m, ShardSet& out) {
  // A count that is not the array's size (a message built by hand) has no box values.
  const bool sized = static_cast<int64_t>(m.shard_box.size()) == m.num_shard_box_values;
  return read_shard_fields({m.shard_rule, m.shard_region_depth, m.shard_index, m.shard_count,
                            sized && !m.shard_box.empty() ? m.shard_box.data() : nullptr, m.num_shard_box_values},
                           out);
}

// "shard 1 of 3 (hash, regions at depth 10)"; "the whole map" when not sharded.
std::string describe(const ShardSet& s);
// Whether two announcements describe the same shard set (rule, count, depth, boxes), whatever
// shard each is.
bool same_shard_set(const ShardSet& a, const ShardSet& b);

}  // namespace ort::protocol

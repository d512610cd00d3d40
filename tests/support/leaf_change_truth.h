// What an octree update really changed, from OctoMap's own search() before and after it, to
// check the octree stage's change log (octree/leaf_changes.h) against.
#pragma once

#include <cstdint>
#include <map>
#include <span>

#include <octomap/OcTree.h>

#include "core/voxel_update.h"
#include "octree/batched/morton_order.h"
#include "octree/leaf_changes.h"

namespace ort::test {

struct KeyValue {
  bool known = false;  // a node covers the key
  float value = 0;
  bool operator==(const KeyValue&) const = default;
};

struct KeyChange {
  bool was_unknown = false;
  float before = 0, after = 0;
  bool operator==(const KeyChange&) const = default;
};

// By Morton code.
using KeyValues = std::map<uint64_t, KeyValue>;
using KeyChanges = std::map<uint64_t, KeyChange>;

// The values search() finds now for the keys of `updates`.
inline KeyValues values_of(const octomap::OcTree& tree, std::span<const VoxelUpdate> updates) {
  KeyValues out;
  for (const VoxelUpdate& u : updates) {
    const octomap::OcTreeNode* n = tree.search(u.key());
    out[morton_code(u.x, u.y, u.z)] = n ? KeyValue{true, n->getLogOdds()} : KeyValue{};
  }
  return out;
}

// The keys whose value differs between two searches (or that had no node before).
inline KeyChanges true_changes(const KeyValues& before, const KeyValues& after) {
  KeyChanges out;
  for (const auto& [code, b] : before) {
    const KeyValue& a = after.at(code);
    if (!b.known || b.value != a.value) out[code] = KeyChange{!b.known, b.known ? b.value : 0.0f, a.value};
  }
  return out;
}

// A change log read as one change per key: the first before, the last after, net no-ops dropped.
inline KeyChanges collapse(const LeafChanges& log) {
  KeyChanges out;
  log.for_each([&](const LeafChange& c) {
    auto [it, fresh] = out.try_emplace(c.morton(), KeyChange{c.was_unknown(), c.before, c.after});
    if (!fresh) it->second.after = c.after;
  });
  std::erase_if(out, [](const auto& kv) { return !kv.second.was_unknown && kv.second.before == kv.second.after; });
  return out;
}

}  // namespace ort::test

// The map's identity: an epoch (which history) and the map state id (how far along it).
// Two readers that saw the same (epoch, id) saw the same map; a state id is only compared
// with ids of its own epoch. Every change to the map of record goes through one of the two
// functions below, under the map's exclusive lock, so nothing changes the map uncounted:
// scans, edits, resets, a loaded prior, and the decay or eviction steps of a long-lived map.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>

#include <octomap/OcTree.h>

namespace ort::daemon {

struct MapState;

// A change other than a scan, replayable on another copy of the map (an edit, a reset, a
// decay or eviction step): it must do the same to any tree equal to the map's.
using MapStep = std::function<void(octomap::OcTree&)>;

// A fresh epoch: random, never 0, below 2^63 (it travels as an int64).
uint64_t new_map_epoch();

// The map changed and its history goes on (a scan, a clear-box, a decay or eviction step):
// the state id grows by one. `leaf_change`: how the change changed the tree's leaf count
// (MapState::leaves), where the changer knows it (the octree stage does); none: the count is
// forgotten until the status counts it again. Returns the new id.
uint64_t count_map_change(MapState& map, std::optional<int64_t> leaf_change = std::nullopt);

// The map's history forks (a reset, another map put in its place): a new epoch, and the
// state id grows by one as for any change. Returns the new id.
uint64_t fork_map_history(MapState& map);

// The one way to change the map other than by a scan (edits, resets, the long-lived map's
// decay and eviction): applies `step` to the map of record's tree, counts it (or, with
// `forks_history`, forks), and replays it on the read replica. Caller holds the map lock
// exclusively. Returns the new state id. A step does not say how it changed the leaves: the
// leaf count is 0 after a step that left the tree empty (a reset), else forgotten.
uint64_t apply_map_step(MapState& map, const MapStep& step, bool forks_history = false);

}  // namespace ort::daemon

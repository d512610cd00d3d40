// Inserting a sequence of scans with the engine's two stages overlapped, for the programs
// that build a map from a known list of scans (`octomap-rt bench`, `octomap-rt build`).
//
// The caller's thread runs stage 1 (MapEngine::shoot_posed: preparation and the GPU); one
// extra thread runs stage 2 (MapEngine::apply: the CPU octree). A hand-off of depth 1
// between them lets scan k+1 be shot while scan k is applied (MapEngine allows shoot() and
// apply() on different scans at once). Scans are applied strictly in order, so the tree is
// the one sequential insertion gives. Without pipelining both stages run on the caller's
// thread, scan after scan, as MapEngine::insert_posed does.
#pragma once

#include <cstddef>
#include <functional>
#include <span>

#include <octomap/OcTree.h>

#include "engine/map_engine.h"

namespace ort {

// One scan's inputs, in the sensor frame (MapEngine::shoot_posed). The points must stay
// valid until stage 1 has shot the scan (the next call of the source, or the return).
struct PosedScanInput {
  octomap::pose6d pose;
  octomap::point3d origin;
  std::span<const octomap::point3d> sensor_points;
};

// Gives scan i's inputs; called on the caller's thread, for i = 0, 1, ... in order.
using ScanInputSource = std::function<PosedScanInput(size_t i)>;
// Sees scan i after it was applied (its ShotScan: voxels, stage times, refusal); called in
// order, one call at a time, on the stage-2 thread when pipelined.
using AppliedScanSink = std::function<void(size_t i, const ShotScan& shot)>;

// Inserts scans 0 .. count-1 into `tree`. Rejected scans (bad origin, refusal) are applied
// as the empty lists they are, as insert_posed does; the sink sees why. An exception in
// either stage or in a callback stops both stages and is rethrown here, once the stage-2
// thread has ended; the tree then holds the scans applied before it.
void insert_scans(MapEngine& engine, size_t count, const ScanInputSource& source, octomap::OcTree& tree,
                  const AppliedScanSink& sink, bool pipelined = true);

}  // namespace ort

// The map on disk: loading a .ot at start (checked whole, refusing another resolution),
// atomic saves, and the start-up check that saves can succeed.
//
// A save never leaves a half-written map under the map's name: the bytes go to FILE.tmp,
// which is fsynced, renamed over FILE (rename is atomic on POSIX file systems), and then the
// directory is fsynced so the rename itself survives a power cut. A crash at any point leaves
// either the previous complete file or the new complete file. A save that fails removes its
// FILE.tmp (a full disk stays no fuller than before).
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

#include <octomap/OcTree.h>

#include "core/sensor_model.h"
#include "octree/map_file_split.h"

namespace ort::daemon {

// Every failure of the map store says what failed (kind) and why (message, with the path
// and the system's reason).
class MapStoreError : public std::runtime_error {
 public:
  enum class Kind {
    kOpen,             // the file cannot be opened
    kRead,             // reading it failed
    kCorrupt,          // not a complete OctoMap .ot file (truncated, overwritten, inconsistent)
    kWrongType,        // an OctoMap file, but not an OcTree
    kWrongResolution,  // an OcTree of another resolution than the server's
    kWrite,            // creating or writing the temporary file failed (e.g. disk full)
    kSync,             // fsync of the file or its directory failed
    kRename,           // the atomic rename failed
    kNotWritable,      // the start-up probe could not write and sync in the map's directory
    kSerialize,        // OctoMap could not serialize the map
    kLocked,           // another daemon holds the map file (daemon/persistence/map_file_lock.h)
  };
  MapStoreError(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

const char* to_string(MapStoreError::Kind kind);

// OctoMap's full format (.ot: AbstractOcTree::write, with log-odds) in memory.
std::string serialize_map(const octomap::OcTree& tree);

// Reads a .ot file whole, checks it (core/file_checks/octree_file_check.h: header, node stream to the
// last byte, node count against the header) and only then lets OctoMap read it. Throws
// MapStoreError: kOpen/kRead, kCorrupt, kWrongType, kWrongResolution (naming both values).
std::unique_ptr<octomap::OcTree> load_map(const std::string& path, double resolution);

// load_map with what the map's identity needs of the file: its size and FNV-1a 64 hash.
// With `bound` (a memory bound, issue 25), the checked file is split before OctoMap reads it
// (octree/map_file_split.h): the tree holds the regions that fit `keep_bytes`, the others go
// to `spill` as region bytes and stay stand-ins, so the whole map is never built in memory.
struct MapLoadBound {
  RegionGrid grid;
  uint64_t keep_bytes = 0;
  RegionSink spill;
};
struct LoadedMapFile {
  std::unique_ptr<octomap::OcTree> tree;
  uint64_t bytes = 0, hash = 0;
  uint64_t spilled_regions = 0, spilled_nodes = 0;  // with a bound: what went to the spill
};
LoadedMapFile load_map_file(const std::string& path, double resolution, const MapLoadBound* bound = nullptr);

// A prior map to start a new map from (octomap_server's map file at start): .ot (log-odds
// kept) or .bt (maximum likelihood: each node at `sensor`'s clamping maximum if occupied,
// minimum if free, as OctoMap's readBinary would give with that sensor model), checked whole
// before OctoMap reads it. Throws MapStoreError like load_map (kWrongResolution: not `resolution`).
// With `bound`, a .ot prior is loaded within it as load_map_file loads the map file.
std::unique_ptr<octomap::OcTree> load_prior_map(const std::string& path, double resolution, const SensorModel& sensor,
                                                const MapLoadBound* bound = nullptr);

// The resolution in an OctoMap file's header (.ot or .bt), read without loading the tree:
// what the server maps at when started without -r. Throws MapStoreError (kOpen, kCorrupt).
double map_file_resolution(const std::string& path);

// Renames `path` to `path`.corrupt-<UTC time> so a new map can start without losing it;
// returns the new name. Throws MapStoreError(kRename).
std::string move_map_aside(const std::string& path);

// Proves at start that saves to `map_path` can succeed: writes, fsyncs and removes a probe
// file in its directory, and removes a FILE.tmp left by an interrupted save. Throws
// MapStoreError(kNotWritable) saying why (read-only, missing directory, disk full, ...).
void check_map_directory_writable(const std::string& map_path);

// Writes `bytes` to `path` atomically (see above). Throws MapStoreError (kWrite, kSync,
// kRename) with errno text; FILE.tmp is gone afterwards whatever happened.
void write_file_atomically(const std::string& path, std::string_view bytes);

}  // namespace ort::daemon

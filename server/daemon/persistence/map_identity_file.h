// The map's identity on disk: FILE.identity beside the map (FILE.ot.identity), written
// atomically after every save of the map (and once at start, marked unclean), so a restart
// knows whether it continues the history it saved (same epoch, same state id) or starts a
// new one. docs/PROTOCOL.md "Ids" states the rule; identity_at_load applies it.
//
// Format (text, "key value" per line, unknown keys ignored):
//   # octomap-rt map identity v1
//   epoch 4f1c2a9d0e3b7765          (hex)
//   state_id 1234
//   map_bytes 530112                (the map file this identity was saved with: its size ...
//   map_hash 9a0c5e7f31d2b804       (... and FNV-1a 64 of its bytes, hex)
//   order_entries 1200              (lines of FILE.order that belong to that map)
//   clean 1                         (1: written by a server's last save at an orderly stop)
//   map_path /abs/path/map.ot
#pragma once

#include <cstdint>
#include <istream>
#include <optional>
#include <string>

namespace ort::daemon {

struct MapIdentityRecord {
  uint64_t epoch = 0, state_id = 0;
  uint64_t map_bytes = 0, map_hash = 0;
  uint64_t order_entries = 0;
  bool clean = false;
  std::string map_path;
  bool operator==(const MapIdentityRecord&) const = default;
};

std::string identity_path(const std::string& map_path);
std::string format_map_identity(const MapIdentityRecord& r);
// Throws std::runtime_error naming the bad line or the missing key.
MapIdentityRecord parse_map_identity(std::istream& in);
// nullopt when there is no such file; throws when it is there but unreadable or malformed.
std::optional<MapIdentityRecord> read_map_identity(const std::string& map_path);

// FNV-1a 64 of a map file's bytes (protocol/map_protocol.h's blob hash, as unsigned).
uint64_t map_file_hash(const std::string& bytes);

// What a map loaded from disk is: the history it continues (epoch, state id), whether that
// is the saved one, and why not.
struct LoadedIdentity {
  uint64_t epoch = 0, state_id = 0;
  bool continued = false;  // same epoch and state id as the server that saved it
  std::string why;         // for the log: why a new epoch (or "continues ...")
};

// The rule: the saved history goes on only when the identity file belongs to exactly this
// file (size and hash: not replaced behind the server's back, not a save cut between the two
// renames), at this path (not a copy another server may continue too), and was written at an
// orderly stop (otherwise ids past the last save may have been announced for changes the
// crash lost). Anything else starts a new epoch; the state id still never goes back
// (max of the saved one and `order_entries`, the scans the order file holds).
LoadedIdentity identity_at_load(const std::optional<MapIdentityRecord>& saved, uint64_t map_bytes, uint64_t map_hash,
                                const std::string& abs_map_path, uint64_t order_entries, uint64_t fresh_epoch);

}  // namespace ort::daemon

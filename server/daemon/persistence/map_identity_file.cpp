#include "daemon/persistence/map_identity_file.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "protocol/map_protocol.h"

namespace ort::daemon {
namespace {

std::string hex(uint64_t v) {
  std::ostringstream o;
  o << std::hex << v;
  return o.str();
}

uint64_t parse_u64(const std::string& text, int base, const std::string& key) {
  size_t used = 0;
  uint64_t v = 0;
  try {
    v = std::stoull(text, &used, base);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || text[0] == '-')
    throw std::runtime_error("map identity: bad value '" + text + "' of " + key);
  return v;
}

}  // namespace

std::string identity_path(const std::string& map_path) { return map_path + ".identity"; }

std::string format_map_identity(const MapIdentityRecord& r) {
  std::string out = "# octomap-rt map identity v1\n";
  out += "epoch " + hex(r.epoch) + "\n";
  out += "state_id " + std::to_string(r.state_id) + "\n";
  out += "map_bytes " + std::to_string(r.map_bytes) + "\n";
  out += "map_hash " + hex(r.map_hash) + "\n";
  out += "order_entries " + std::to_string(r.order_entries) + "\n";
  out += std::string("clean ") + (r.clean ? "1" : "0") + "\n";
  out += "map_path " + r.map_path + "\n";
  return out;
}

MapIdentityRecord parse_map_identity(std::istream& in) {
  MapIdentityRecord r;
  std::string line;
  unsigned seen = 0;
  enum : unsigned { kEpoch = 1, kState = 2, kBytes = 4, kHash = 8, kOrder = 16, kClean = 32, kAll = 63 };
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const size_t space = line.find(' ');
    const std::string key = line.substr(0, space), value = space == std::string::npos ? "" : line.substr(space + 1);
    if (key == "epoch")
      r.epoch = parse_u64(value, 16, key), seen |= kEpoch;
    else if (key == "state_id")
      r.state_id = parse_u64(value, 10, key), seen |= kState;
    else if (key == "map_bytes")
      r.map_bytes = parse_u64(value, 10, key), seen |= kBytes;
    else if (key == "map_hash")
      r.map_hash = parse_u64(value, 16, key), seen |= kHash;
    else if (key == "order_entries")
      r.order_entries = parse_u64(value, 10, key), seen |= kOrder;
    else if (key == "clean")
      r.clean = parse_u64(value, 10, key) != 0, seen |= kClean;
    else if (key == "map_path")
      r.map_path = value;
  }
  if (seen != kAll)
    throw std::runtime_error(
        "map identity: a key is missing (epoch, state_id, map_bytes, map_hash, order_entries, clean)");
  if (r.epoch == 0 || r.epoch >> 63) throw std::runtime_error("map identity: epoch out of range");
  return r;
}

std::optional<MapIdentityRecord> read_map_identity(const std::string& map_path) {
  const std::string path = identity_path(map_path);
  if (!std::filesystem::exists(path)) return std::nullopt;
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open '" + path + "'");
  try {
    return parse_map_identity(in);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("'" + path + "': " + e.what());
  }
}

uint64_t map_file_hash(const std::string& bytes) {
  return static_cast<uint64_t>(protocol::blob_hash(bytes.data(), bytes.size()));
}

LoadedIdentity identity_at_load(const std::optional<MapIdentityRecord>& saved, uint64_t map_bytes, uint64_t map_hash,
                                const std::string& abs_map_path, uint64_t order_entries, uint64_t fresh_epoch) {
  LoadedIdentity id;
  id.epoch = fresh_epoch;
  id.state_id = std::max(order_entries, saved ? saved->state_id : 0);
  if (!saved) {
    id.why = "no identity file beside it (a map from elsewhere or from an older server): a new history";
  } else if (saved->map_bytes != map_bytes || saved->map_hash != map_hash) {
    id.why = "its identity file belongs to another version of the file (replaced, or a save cut short): a new history";
  } else if (saved->map_path != abs_map_path) {
    id.why = "it was saved as '" + saved->map_path + "' (a copy may go on there too): a new history";
  } else if (!saved->clean) {
    id.why = "the server that saved it did not stop cleanly (changes after its last save are lost): a new history";
  } else {
    id.epoch = saved->epoch;
    id.state_id = saved->state_id;
    id.continued = true;
    id.why = "continues its saved history";
  }
  return id;
}

}  // namespace ort::daemon

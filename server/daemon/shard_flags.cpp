#include "daemon/shard_flags.h"

#include <cmath>
#include <cstdlib>

#include "protocol/channels.h"

namespace ort::daemon {
namespace {

// "X0,Y0,Z0:X1,Y1,Z1" (strtod's numbers: inf and -inf too); false when it is not.
bool parse_box(const std::string& text, double min[3], double max[3]) {
  const char* p = text.c_str();
  for (int k = 0; k < 6; ++k) {
    char* end = nullptr;
    const double v = std::strtod(p, &end);
    if (end == p || std::isnan(v)) return false;
    (k < 3 ? min[k] : max[k - 3]) = v;
    const char want = k == 2 ? ':' : (k == 5 ? '\0' : ',');
    if (*end != want) return false;
    p = end + (want ? 1 : 0);
  }
  for (int k = 0; k < 3; ++k)
    if (!(min[k] < max[k])) return false;
  return true;
}

}  // namespace

void add_shard_flags(CLI::App& app, ShardFlags& f) {
  app.add_option("--shard", f.shard,
                 "be shard i of N daemons mapping this namespace's scans side by side (0 <= i < N): map only the "
                 "regions the set's rule gives shard i (hash of the region, or --shard-box); the map protocol, "
                 "queries and edits move to the channels of namespace [NS_]SHARD<i>, scans and status stay");
  app.add_option("--shard-box", f.boxes,
                 "the shard set's boxes in metres, X0,Y0,Z0:X1,Y1,Z1 (inf allowed), one per shard in shard order "
                 "(repeat): shard i owns the regions whose min corner lies in box i; the boxes must cover the key "
                 "space without overlap");
  app.add_option("--shard-region-depth", f.region_depth,
                 "octree depth of the regions shards own (13: 8 voxels a side; coarser regions balance the "
                 "hash rule's shards worse, docs/BENCHMARKS.md \"Shards\")")
      ->capture_default_str();
}

protocol::ShardSet to_shard_set(const ShardFlags& f, double resolution) {
  protocol::ShardSet set;
  if (f.shard.empty()) {
    if (!f.boxes.empty()) throw CLI::ValidationError("--shard-box", "needs --shard i/N");
    return set;
  }
  if (const std::string why = protocol::parse_shard_index(f.shard, set.index, set.count); !why.empty())
    throw CLI::ValidationError("--shard", why);
  if (f.region_depth < 1 || f.region_depth > 16)
    throw CLI::ValidationError("--shard-region-depth", "must be within 1 .. 16");
  set.region_depth = f.region_depth;
  set.rule = f.boxes.empty() ? protocol::ShardRule::kHash : protocol::ShardRule::kBoxes;
  for (const std::string& text : f.boxes) {
    double min[3], max[3];
    if (!parse_box(text, min, max))
      throw CLI::ValidationError("--shard-box",
                                 "'" + text + "' is not X0,Y0,Z0:X1,Y1,Z1 with X0 < X1, Y0 < Y1, Z0 < Z1");
    set.boxes.push_back(protocol::region_box_of(min, max, resolution, set.region_depth));
  }
  if (const std::string why = protocol::check_shard_set(set); !why.empty()) {
    const double side = resolution * double(1u << (16 - set.region_depth));
    throw CLI::ValidationError("--shard/--shard-box", why + " (a region is " + std::to_string(side) +
                                                          " m a side; region r starts at (r * side - " +
                                                          std::to_string(32768 * resolution) + ") m)");
  }
  return set;
}

void keep_shared_channels(ServerConfig& c, const ServerConfig& given, const std::string& ns) {
  c.scan_channels = protocol::in_namespace(ns, given.scan_channels);
  c.status.channel = protocol::in_namespace(ns, given.status.channel);
  c.queries.status_channel = c.status.channel;
  c.queries.scan_prefix = protocol::in_namespace(ns, protocol::kScanChannelPrefix);
  c.ns = ns;
}

}  // namespace ort::daemon

#include "shard_client/shard_mirror.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "core/clock.h"
#include "map_client/map_client.h"
#include "map_client/shard_merge.h"
#include "protocol/shards/shard_wire.h"

namespace ort::client {

// The client before the mirror: the mirror registers its handlers on the client. Held by
// unique_ptr, so the info handler's `this` stays put.
struct ShardMirror::Shard {
  Shard(uint32_t i, const std::string& url, const std::string& served_in, MirrorOptions o,
        const protocol::ShardSet& set)
      : index(i), client(url, ClientOptions{}.in_namespace(served_in)), mirror(client, with_check(std::move(o), set)) {}

  MirrorOptions with_check(MirrorOptions o, const protocol::ShardSet& set) {
    o.on_info = [this, &set](const octomap_rt::map_info_t& info) {
      protocol::ShardSet heard;
      const bool ok = protocol::read_shard_set(info, heard) == protocol::ShardFieldFault::kNone &&
                      protocol::same_shard_set(set, heard) && heard.index == index;
      if (!ok) {
        refused_infos++;
        return;
      }
      last_info_utime = now_utime();
    };
    return o;
  }

  uint32_t index;
  MapClient client;
  MapMirror mirror;
  int64_t last_info_utime = 0, refused_infos = 0;
  int64_t retry_after_utime = 0;  // set by a failed fetch
  std::string error = "no snapshot fetched yet";
};

ShardMirror::ShardMirror(const std::string& url, const std::string& ns, const protocol::ShardSet& set,
                         ShardMirrorOptions opts)
    : set_(set), opts_(std::move(opts)) {
  if (const std::string why = protocol::check_shard_set(set_); !why.empty())
    throw std::invalid_argument("shard set: " + why);
  for (uint32_t i = 0; i < set_.count; ++i) {
    // A server that is not sharded serves on the namespace itself.
    const std::string served_in = set_.sharded() ? protocol::shard_namespace(ns, i) : ns;
    shards_.push_back(std::make_unique<Shard>(i, url, served_in, opts_.mirror, set_));
  }
}

ShardMirror::~ShardMirror() = default;

void ShardMirror::try_sync(Shard& s) {
  try {
    s.mirror.sync();
    s.error.clear();
  } catch (const std::exception& e) {
    s.error = e.what();
    s.retry_after_utime = now_utime() + static_cast<int64_t>(opts_.retry_s * 1e6);
  }
}

void ShardMirror::sync() {
  for (auto& s : shards_)
    if (!s->mirror.synced()) try_sync(*s);
}

void ShardMirror::spin(double seconds) {
  const auto t0 = SteadyClock::now();
  // Each shard's socket keeps what arrives while another shard is handled; a short slice each
  // keeps them all drained.
  const double slice = 0.01;
  do {
    for (auto& s : shards_) {
      if (!s->error.empty()) {  // not synced, or its last resync failed: retry after a pause
        if (now_utime() < s->retry_after_utime) {
          s->client.spin(0);  // still hear its infos (and say it is alive)
          continue;
        }
        try_sync(*s);
        if (!s->error.empty()) continue;
      }
      try {
        s->mirror.spin(slice);  // resyncs there on a gap or a new epoch
      } catch (const std::exception& e) {
        s->error = e.what();
        s->retry_after_utime = now_utime() + static_cast<int64_t>(opts_.retry_s * 1e6);
      }
    }
  } while (seconds_since(t0) < seconds);
}

std::vector<ShardMirrorPart> ShardMirror::parts() const {
  std::vector<ShardMirrorPart> out;
  for (const auto& s : shards_) {
    ShardMirrorPart p;
    p.index = s->index;
    p.synced = s->mirror.synced();
    p.version = s->mirror.version();
    p.epoch = s->mirror.epoch();
    p.stats = s->mirror.stats();
    p.last_info_utime = s->last_info_utime;
    p.refused_infos = s->refused_infos;
    p.error = s->error;
    out.push_back(std::move(p));
  }
  return out;
}

const MapMirror& ShardMirror::shard(uint32_t index) const {
  if (index >= shards_.size()) throw std::out_of_range("no shard " + std::to_string(index));
  return shards_[index]->mirror;
}

std::vector<uint32_t> ShardMirror::missing() const {
  std::vector<uint32_t> out;
  for (const auto& s : shards_)
    if (!s->mirror.synced()) out.push_back(s->index);
  return out;
}

std::vector<uint32_t> ShardMirror::late(int64_t now) const {
  std::vector<uint32_t> out;
  for (const auto& s : shards_)
    if (s->mirror.synced() && double(now - s->last_info_utime) > opts_.late_after_s * 1e6) out.push_back(s->index);
  return out;
}

std::string ShardMirror::shortfall(int64_t now) const {
  std::string out;
  auto add = [&](const std::string& s) { out += (out.empty() ? "" : "; ") + s; };
  const std::string of = " of " + std::to_string(set_.count);
  for (uint32_t i : missing()) add("shard " + std::to_string(i) + of + " missing: " + shards_[i]->error);
  for (const auto& s : shards_)  // holds an older snapshot's map, its resync failed
    if (s->mirror.synced() && !s->error.empty())
      add("shard " + std::to_string(s->index) + of + " behind (resync failed: " + s->error + ")");
  for (uint32_t i : late(now)) {
    char why[96];
    if (shards_[i]->last_info_utime == 0)
      std::snprintf(why, sizeof why, " late (no map info heard)");
    else
      std::snprintf(why, sizeof why, " late (no map info for %.1f s)",
                    double(now - shards_[i]->last_info_utime) * 1e-6);
    add("shard " + std::to_string(i) + of + why);
  }
  return out;
}

MergedMirror ShardMirror::merged(int64_t now) const {
  MergedMirror m;
  m.missing = missing();
  m.late = late(now);
  m.shortfall = shortfall(now);
  std::vector<const octomap::OcTree*> views;
  for (const auto& s : shards_)
    if (s->mirror.synced()) views.push_back(&s->mirror.tree());
  if (!views.empty()) m.tree = merge_shard_trees(views, set_.region_depth);
  return m;
}

}  // namespace ort::client

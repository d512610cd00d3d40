// `octomap-rt map watch`: a MapMirror on the command line, one line a second; with --shards a
// ShardMirror (every shard's deltas, merged), each shard's version and epoch on the line and a
// missing or late shard named on it.
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <stdexcept>

#include "cli/map_commands.h"
#include "core/clock.h"
#include "map_client/map_mirror.h"
#include "protocol/channels.h"
#include "protocol/lcm_url.h"
#include "shard_client/shard_mirror.h"
#include "shard_client/shard_roster.h"

namespace ort::cli {
namespace {

struct ClassCounts {
  size_t occupied = 0, free = 0;
};

ClassCounts count_classes(const octomap::OcTree& t) {
  ClassCounts c;
  for (auto it = t.begin_leafs(), end = t.end_leafs(); it != end; ++it) {
    const size_t n = size_t{1} << (3 * (t.getTreeDepth() - it.getDepth()));  // finest voxels it stands for
    (t.isNodeOccupied(*it) ? c.occupied : c.free) += n;
  }
  return c;
}

// Ctrl-C ends the watch: SIGINT is blocked here and polled, so no handler and no global flag.
bool interrupted(const sigset_t& s) {
  timespec zero{0, 0};
  return sigtimedwait(&s, nullptr, &zero) > 0;
}

// Ctrl-C and SIGTERM polled (interrupted()). `map watch | head`: when the reader goes away, a
// write fails (EPIPE) instead of killing the process, the watch ends and --save still writes.
sigset_t watch_signals() {
  sigset_t sigs;
  sigemptyset(&sigs);
  sigaddset(&sigs, SIGINT);
  sigaddset(&sigs, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &sigs, nullptr);
  ::signal(SIGPIPE, SIG_IGN);
  return sigs;
}

// Returns 0, or 3 when the last screen was partial or late (the saved map says so too).
int run_shard_watch(const MapArgs& a) {
  const sigset_t sigs = watch_signals();
  const std::string url = ort::protocol::lcm_url_or_default(a.lcm_url);
  const std::string ns = protocol::namespace_from(a.ns);
  const client::ShardRoster roster = client::discover_shards(url, ns, std::min(a.timeout_s, 5.0));
  if (!roster.set()) throw std::runtime_error("no shard of namespace '" + ns + "' sent a status");
  client::ShardMirrorOptions o;
  o.mirror.fetch_timeout_s = a.timeout_s;
  client::ShardMirror m(url, ns, *roster.set(), o);
  m.sync();
  const auto t0 = SteadyClock::now();
  auto elapsed = [&] { return seconds_since(t0); };
  std::string shortfall;
  bool reader_gone = false;
  while (!reader_gone && !interrupted(sigs) && (a.seconds <= 0 || elapsed() < a.seconds)) {
    m.spin(1.0);
    const client::MergedMirror merged = m.merged(now_utime());
    shortfall = merged.shortfall;
    const ClassCounts k = merged.tree ? count_classes(*merged.tree) : ClassCounts{};
    std::string shards;
    for (const client::ShardMirrorPart& p : m.parts()) {
      char one[256];
      if (a.json)
        std::snprintf(one, sizeof one,
                      "%s{\"index\": %u, \"synced\": %s, \"version\": %lld, \"epoch\": %lld, \"deltas\": %lld, "
                      "\"gaps\": %lld, \"snapshots\": %lld}",
                      p.index ? ", " : "", p.index, p.synced ? "true" : "false", (long long)p.version,
                      (long long)p.epoch, (long long)p.stats.deltas_applied, (long long)p.stats.gaps,
                      (long long)p.stats.snapshots);
      else
        std::snprintf(one, sizeof one, "  shard %u: version %lld epoch %lld gaps %lld snapshots %lld", p.index,
                      (long long)p.version, (long long)p.epoch, (long long)p.stats.gaps, (long long)p.stats.snapshots);
      shards += one;
    }
    if (a.json)
      std::printf(
          "{\"t\": %.1f, \"occupied\": %zu, \"free\": %zu, \"partial\": %s, \"shortfall\": \"%s\", "
          "\"shards\": [%s]}\n",
          elapsed(), k.occupied, k.free, merged.partial() ? "true" : "false", shortfall.c_str(), shards.c_str());
    else
      std::printf("%6.1f s  occupied %zu  free %zu voxels%s%s\n", elapsed(), k.occupied, k.free, shards.c_str(),
                  shortfall.empty() ? "" : ("  PARTIAL: " + shortfall).c_str());
    reader_gone = std::fflush(stdout) != 0 || std::ferror(stdout);
  }
  if (!a.save.empty()) {
    const client::MergedMirror merged = m.merged(now_utime());
    if (!merged.tree || !merged.tree->write(a.save)) throw std::runtime_error("cannot write '" + a.save + "'");
    std::fprintf(reader_gone ? stderr : stdout, "merged mirror of %u shards saved to %s%s\n", m.set().count,
                 a.save.c_str(), merged.shortfall.empty() ? "" : (" PARTIAL: " + merged.shortfall).c_str());
    shortfall = merged.shortfall;
  }
  return shortfall.empty() ? 0 : 3;
}

}  // namespace

int run_map_watch(const MapArgs& a) {
  if (a.shards) return run_shard_watch(a);
  const sigset_t sigs = watch_signals();
  client::MapClient c(ort::protocol::lcm_url_or_default(a.lcm_url),
                      client::ClientOptions{}.in_namespace(protocol::namespace_from(a.ns)));
  client::MirrorOptions o;
  o.fetch_timeout_s = a.timeout_s;
  client::MapMirror m(c, o);
  m.sync();
  std::printf("mirror of snapshot %lld\n", (long long)m.version());
  const auto t0 = SteadyClock::now();
  auto elapsed = [&] { return seconds_since(t0); };
  int64_t last_deltas = 0, last_bytes = 0;
  bool reader_gone = false;
  while (!reader_gone && !interrupted(sigs) && (a.seconds <= 0 || elapsed() < a.seconds)) {
    m.spin(1.0);
    const client::MirrorStats& s = m.stats();
    const ClassCounts k = count_classes(m.tree());
    if (a.json)
      std::printf(
          "{\"t\": %.1f, \"version\": %lld, \"deltas_per_s\": %lld, \"bytes_per_s\": %lld, \"occupied\": %zu, "
          "\"free\": %zu, \"gaps\": %lld, \"snapshots\": %lld}\n",
          elapsed(), (long long)m.version(), (long long)(s.deltas_applied - last_deltas),
          (long long)(s.delta_bytes - last_bytes), k.occupied, k.free, (long long)s.gaps, (long long)s.snapshots);
    else
      std::printf(
          "%6.1f s  version %lld  %lld deltas/s  %.1f KB/s  occupied %zu  free %zu voxels  gaps %lld  "
          "snapshots %lld\n",
          elapsed(), (long long)m.version(), (long long)(s.deltas_applied - last_deltas),
          (s.delta_bytes - last_bytes) / 1000.0, k.occupied, k.free, (long long)s.gaps, (long long)s.snapshots);
    reader_gone = std::fflush(stdout) != 0 || std::ferror(stdout);
    last_deltas = s.deltas_applied;
    last_bytes = s.delta_bytes;
  }
  if (!a.save.empty()) {
    if (!m.tree().write(a.save)) throw std::runtime_error("cannot write '" + a.save + "'");
    std::fprintf(reader_gone ? stderr : stdout, "mirror at version %lld saved to %s\n", (long long)m.version(),
                 a.save.c_str());
  }
  return 0;
}

}  // namespace ort::cli

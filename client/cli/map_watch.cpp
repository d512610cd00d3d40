// `octomap-rt map watch`: a MapMirror on the command line, one line a second.
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <stdexcept>

#include "cli/map_commands.h"
#include "core/clock.h"
#include "map_client/map_mirror.h"
#include "protocol/channels.h"
#include "protocol/lcm_url.h"

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

}  // namespace

void run_map_watch(const MapArgs& a) {
  sigset_t sigs;
  sigemptyset(&sigs);
  sigaddset(&sigs, SIGINT);
  sigaddset(&sigs, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &sigs, nullptr);
  // `map watch | head`: when the reader goes away, a write fails (EPIPE) instead of killing the
  // process, the watch ends and --save still writes the mirror.
  ::signal(SIGPIPE, SIG_IGN);
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
}

}  // namespace ort::cli

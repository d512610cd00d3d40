// map_fetch LCM_URL: fetches the server's map, then mirrors it for two seconds.
// Built against the installed octomap_rt package (find_package(octomap_rt)).
#include <cstdio>
#include <exception>

#include "map_client/map_mirror.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: map_fetch LCM_URL\n");
    return 2;
  }
  try {
    ort::client::MapClient client(argv[1]);
    const ort::client::FetchedSnapshot s =
        client.fetch_snapshot(octomap_rt::map_chunk_t::FORMAT_OCTOMAP_FULL, /*timeout_s=*/30);
    const auto tree = s.tree();
    std::printf("snapshot %lld: %lld scans, %zu nodes at %g m\n", (long long)s.snapshot_id, (long long)s.num_scans,
                tree->size(), tree->getResolution());
    ort::client::MapMirror mirror(client);
    mirror.sync();
    mirror.spin(2.0);
    std::printf("mirror at map state %lld, %zu nodes\n", (long long)mirror.version(), mirror.tree().size());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "map_fetch: %s\n", e.what());
    return 1;
  }
  return 0;
}

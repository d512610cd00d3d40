// query_point LCM_URL X Y Z: what the server's map says about one point (occupied, free or
// unknown, with the map state it read). Built against the installed octomap_rt package
// (find_package(octomap_rt), target octomap_rt::query_client), with one namespace: ort::client.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "query_client/client.h"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: query_point LCM_URL X Y Z\n");
    return 2;
  }
  try {
    namespace oc = ort::client;
    oc::QueryClient query(oc::lcm_url_or_default(argv[1]), "query-point", std::chrono::seconds(10),
                          oc::namespace_from(""));
    const oc::OccupancyReply r =
        query.points({std::strtof(argv[2], nullptr), std::strtof(argv[3], nullptr), std::strtof(argv[4], nullptr)});
    if (r.status != oc::OccupancyReply::REPLY_OK) {
      std::fprintf(stderr, "query_point: refused: %s\n", r.error.c_str());
      return 1;
    }
    const int8_t s = r.occupancy.empty() ? oc::OccupancyReply::OCC_UNKNOWN : r.occupancy[0];
    std::printf("map state %lld: %s\n", (long long)r.snapshot_id,
                s == oc::OccupancyReply::OCC_OCCUPIED ? "occupied"
                : s == oc::OccupancyReply::OCC_FREE   ? "free"
                                                      : "unknown");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "query_point: %s\n", e.what());
    return 1;
  }
  return 0;
}

// Issue 21: the server's own flags that feed the ray walk and the sensor model are range-checked
// at start: each absurd value ends the server at once, before it maps anything, with an error
// that names the flag.
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

namespace {

struct ServerRun {
  int exit = -1;
  std::string output;
};

// The server with `flags` (and a memq:// bus, no map file); `timeout` ends one that started.
ServerRun run_server(const std::string& flags) {
  ServerRun r;
  const std::string cmd =
      std::string("timeout 20 ") + OCTOMAP_RT_SERVER + " --lcm-url memq:// --backend cpu " + flags + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, p)) r.output.append(buf, n);
  const int status = pclose(p);
  r.exit = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

TEST(ServerFlags, AbsurdNumbersForTheWalkAndTheSensorModelAreRefusedAtStart) {
  const struct {
    const char* flags;
    const char* names;
  } cases[] = {
      {"-r 0.1 --max-range 1e-30", "--max-range"},  // every cut ray degenerate (the crash)
      {"-r 0.1 --max-range 0", "--max-range"},
      {"-r 0.1 --max-range 0.0005", "--max-range"},
      {"-r 0.1 --max-range nan", "--max-range"},
      {"-r 0.1 --max-range inf", "--max-range"},
      {"-r 0", "--resolution"},
      {"-r 1e-300", "--resolution"},
      {"-r 1e300", "--resolution"},
      {"-r nan", "--resolution"},
      {"-r -0.1", "--resolution"},
      {"-r 0.1 --prob-hit 1", "--prob-hit"},
      {"-r 0.1 --prob-hit 0", "--prob-hit"},
      {"-r 0.1 --prob-hit nan", "--prob-hit"},
      {"-r 0.1 --prob-miss 1.5", "--prob-miss"},
      {"-r 0.1 --prob-miss -0.1", "--prob-miss"},
      {"-r 0.1 --clamp-min 0", "--clamp-min"},
      {"-r 0.1 --clamp-max 1", "--clamp-max"},
      {"-r 0.1 --clamp-min 0.9 --clamp-max 0.2", "--clamp-min"},
      {"-r 0.1 --occupancy-threshold 1", "--occupancy-threshold"},
      // Issue 24's filters: inverted or NaN limits, a negative min range, an inverted band.
      {"-r 0.1 --pointcloud-min-z 2 --pointcloud-max-z 1", "--pointcloud"},
      {"-r 0.1 --sensor-max-x nan", "--sensor"},
      {"-r 0.1 --min-range -1", "--min-range"},
      {"-r 0.1 --occupancy-min-z 3 --occupancy-max-z 1", "--occupancy-min-z"},
      // Issue 21's cost bounds over time: NaN or negative rates and allowances.
      {"-r 0.1 --max-new-nodes-per-s nan", "--max-new-nodes-per-s"},
      {"-r 0.1 --max-map-new-nodes-per-s -1", "--max-map-new-nodes-per-s"},
      {"-r 0.1 --map-new-node-burst nan", "--map-new-node-burst"},
      {"-r 0.1 --max-origin-jump -5", "--max-origin-jump"},
      // The shared class's share and the per-scan time bound: NaN, zero share, negative time.
      {"-r 0.1 --shared-class-share nan", "--shared-class-share"},
      {"-r 0.1 --shared-class-share 0", "--shared-class-share"},
      {"-r 0.1 --max-scan-time -1", "--max-scan-time"},
      {"-r 0.1 --max-scan-time nan", "--max-scan-time"},
      // Shard regions: depth 0 and past the octree's 16 levels.
      {"-r 0.1 --shard 0/2 --shard-region-depth 0", "--shard-region-depth"},
      {"-r 0.1 --shard 0/2 --shard-region-depth 17", "--shard-region-depth"},
      // The memory bound's working set: NaN, negative.
      {"-r 0.1 --working-set-seconds nan", "--working-set-seconds"},
      {"-r 0.1 --working-set-seconds -1", "--working-set-seconds"},
  };
  for (const auto& c : cases) {
    const ServerRun r = run_server(c.flags);
    EXPECT_NE(r.exit, 0) << c.flags << ":\n" << r.output;
    EXPECT_NE(r.exit, 124) << c.flags << " started the server:\n" << r.output;
    EXPECT_NE(r.output.find(c.names), std::string::npos) << c.flags << ":\n" << r.output;
  }
}

}  // namespace

// Issue 13, findings 5, 6 and 7: `octomap-rt build` and `replay` on hostile or unlucky input.
// Truncated or inconsistent .graph files (and a header claiming 2^31-1 scans) are refused
// with a message and a non-zero exit, never an abort (134); a map written to a full disk is
// an error; non-finite or absurd resolutions, rates and ranges are refused; a resolution
// that puts every point outside the key range gets a warning.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "cli/octomap_chatter.h"
#include "scene/scan_set.h"
#include "support/test_data.h"

namespace ort::test {
namespace {

struct CliRun {
  int exit = -1;
  std::string output;
};

CliRun run(const std::string& args) {
  CliRun r;
  const std::string cmd = std::string(OCTOMAP_RT_CLI) + " " + args + " 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int st = ::pclose(p);
  r.exit = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  return r;
}

std::string dir() {
  static const std::string d = [] {
    const std::string p = testing::TempDir() + "/cli_input_test";
    std::filesystem::remove_all(p);
    std::filesystem::create_directories(p);
    return p;
  }();
  return d;
}

// A .graph of one scan from the origin: 20 points `range` m ahead along x, 0.1 m apart.
std::string one_scan_graph(float range, const std::string& name) {
  ScanSet set;
  PosedScan s;
  s.pose = octomap::pose6d(0, 0, 0, 0, 0, 0);
  for (int i = 0; i < 20; ++i) s.points.push_back(range, 0.1f * i, 0.5f);
  set.scans.push_back(s);
  const std::string graph = dir() + "/" + name;
  save_scan_graph(set, graph);
  return graph;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string write_file(const std::string& name, const std::string& bytes) {
  const std::string path = dir() + "/" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

void expect_refused(const CliRun& r, const std::string& needle, const std::string& what) {
  EXPECT_NE(r.exit, 0) << what << ":\n" << r.output;
  EXPECT_NE(r.exit, 134) << what << " aborted:\n" << r.output;
  EXPECT_LT(r.exit, 128) << what << " died of a signal:\n" << r.output;
  EXPECT_NE(r.output.find(needle), std::string::npos) << what << ": no '" << needle << "' in:\n" << r.output;
}

TEST(CliInput, BrokenScanGraphsAreRefusedWithAMessage) {
  const std::string graph = data_file("octomap_share/spherical_scan.graph");
  ASSERT_FALSE(graph.empty());
  const std::string good = read_file(graph);
  ASSERT_GT(good.size(), 1000u);
  std::string huge = good;
  const uint32_t claim = 0x7fffffff;
  std::memcpy(huge.data(), &claim, 4);
  std::string points = good;  // the first scan claims more points than the file holds
  const uint32_t many = 0x10000000;
  std::memcpy(points.data() + 4, &many, 4);
  const struct {
    const char* name;
    std::string bytes;
    const char* needle;
  } cases[] = {
      {"half.graph", good.substr(0, good.size() / 2), "not a valid OctoMap ScanGraph"},
      {"short.graph", good.substr(0, good.size() - 3), "not a valid OctoMap ScanGraph"},
      {"tiny.graph", good.substr(0, 2), "not a valid OctoMap ScanGraph"},
      {"huge.graph", huge, "2147483647 scans"},
      {"points.graph", points, "268435456 points"},
  };
  for (const auto& c : cases) {
    const std::string path = write_file(c.name, c.bytes);
    expect_refused(run("build " + path + " -r 0.2 --backend cpu -q -o " + dir() + "/out.bt"), c.needle,
                   std::string("build ") + c.name);
    expect_refused(run("replay " + path + " --robot r1 --lcm-url memq:// -q"), c.needle,
                   std::string("replay ") + c.name);
  }
  // The intact file still builds.
  const CliRun ok = run("build " + graph + " -r 0.2 --backend cpu -q -o " + dir() + "/ok.bt");
  EXPECT_EQ(ok.exit, 0) << ok.output;
}

TEST(CliInput, AMapThatCannotBeWrittenIsAnError) {
  // A full disk: the output is a link to /dev/full, which takes the open and fails the writes.
  for (const char* ext : {".bt", ".ot"}) {
    const std::string out = dir() + "/full" + ext;
    std::filesystem::remove(out);
    std::filesystem::create_symlink("/dev/full", out);
    const CliRun r = run("build synthetic -r 0.2 --backend cpu -q -o " + out);
    expect_refused(r, "could not write the map", std::string("build -o /dev/full as ") + ext);
    EXPECT_EQ(r.output.find("map written to"), std::string::npos) << r.output;
  }
  expect_refused(run("build synthetic -r 0.2 --backend cpu -q -o " + dir() + "/no-such-dir/map.bt"), "cannot create",
                 "build -o into a missing directory");
}

TEST(CliInput, NonFiniteOrAbsurdNumbersAreRefused) {
  const std::string build = "build synthetic --backend cpu -q -o " + dir() + "/x.bt ";
  expect_refused(run(build + "-r nan"), "--resolution", "-r nan");
  expect_refused(run(build + "-r inf"), "--resolution", "-r inf");
  expect_refused(run(build + "-r 1e-300"), "--resolution", "-r 1e-300");
  expect_refused(run(build + "-r 1e300"), "--resolution", "-r 1e300");
  expect_refused(run(build + "-r 0.2 --max-range nan"), "--max-range", "build --max-range nan");
  // Issue 21: a positive max range far below the resolution made every cut ray degenerate.
  for (const char* r : {"1e-30", "0", "0.0009"})
    expect_refused(run(build + "-r 0.2 --max-range " + r), "--max-range", std::string("build --max-range ") + r);
  const std::string replay = "replay synthetic --robot r1 --lcm-url memq:// -q ";
  for (const char* rate : {"0", "-1", "nan", "inf"})
    expect_refused(run(replay + "--rate " + rate), "--rate", std::string("replay --rate ") + rate);
  expect_refused(run(replay + "--max-range nan"), "--max-range", "replay --max-range nan");
  expect_refused(run(replay + "--max-range 1e-30"), "--max-range", "replay --max-range 1e-30");
  expect_refused(run(replay + "--speed nan"), "--speed", "replay --speed nan");
  const CliRun ok = run(replay + "--unpaced --count 2");
  EXPECT_EQ(ok.exit, 0) << ok.output;
}

TEST(CliInput, EveryPointOutsideTheKeyRangeIsSaidOutLoud) {
  // At 0.1 mm the key range is +-3.3 m: a sensor at the origin seeing points 10 m away.
  const std::string graph = one_scan_graph(10.0f, "far.graph");
  const CliRun r = run("build " + graph + " -r 0.0001 --backend cpu -q -o " + dir() + "/empty.bt");
  EXPECT_EQ(r.exit, 0) << r.output;
  EXPECT_NE(r.output.find("the map is empty; is the resolution right?"), std::string::npos) << r.output;
}

TEST(CliInput, OctomapsReadProgressLinesDoNotReachTheUser) {
  // OctoMap writes "Reading binary octree type OcTree" (and for .ot "Reading octree type
  // OcTree", "Done (N nodes)") to stderr on every tree it reads; octomap-rt drops those
  // lines and nothing else.
  octomap::OcTree tree(0.1);
  tree.updateNode(octomap::point3d(1, 1, 1), true);
  const std::string bt = dir() + "/one.bt", ot = dir() + "/one.ot";
  ASSERT_TRUE(tree.writeBinary(bt));
  ASSERT_TRUE(tree.write(ot));
  const CliRun same = run("map diff " + bt + " " + ot);
  EXPECT_EQ(same.exit, 0) << same.output;
  EXPECT_FALSE(same.output.empty());
  for (const char* chatter : {"Reading binary octree type", "Reading octree type", "Done ("})
    EXPECT_EQ(same.output.find(chatter), std::string::npos) << same.output;
  const CliRun missing = run("map diff " + bt + " " + dir() + "/none.bt");
  EXPECT_NE(missing.exit, 0);
  EXPECT_NE(missing.output.find("none.bt"), std::string::npos) << missing.output;  // errors still pass
}

TEST(CliInput, OctomapsStdioProgressLinesDoNotReachTheUser) {
  // OctoMap also prints through C stdio's stderr: "Reading N points from binary file...done."
  // for every cloud of a .graph, "Writing N nodes to output stream... done." for every .bt
  // writeBinary writes (`map get --shards -o FILE.bt`). octomap-rt drops those lines and
  // nothing else: its own messages and OctoMap's warnings pass.
  const std::string graph = one_scan_graph(2.0f, "stdio.graph");
  const CliRun built = run("build " + graph + " -r 0.1 --backend cpu -q -o " + dir() + "/stdio.bt");
  EXPECT_EQ(built.exit, 0) << built.output;
  EXPECT_EQ(built.output.find("points from binary file"), std::string::npos) << built.output;
  EXPECT_NE(built.output.find("octomap-rt build: 1 scans, 20 points"), std::string::npos) << built.output;

  // The filter the CLI's main holds, around what `map get --shards` does to write a .bt.
  const std::string captured = dir() + "/stderr.txt";
  std::fflush(stderr);
  const int saved = ::dup(2);
  FILE* into = std::fopen(captured.c_str(), "w");
  ASSERT_NE(into, nullptr);
  ::dup2(::fileno(into), 2);
  {
    const cli::OctomapStdioFilter quiet;
    octomap::OcTree tree(0.1);
    tree.updateNode(octomap::point3d(1, 1, 1), true);
    std::ostringstream bt;
    tree.writeBinary(bt);
    std::fprintf(stderr, "WARNING: kept\n");
    std::fprintf(stderr, "Writing is what we do");  // no newline: passes when the filter goes
  }
  std::fflush(stderr);
  ::dup2(saved, 2);
  ::close(saved);
  std::fclose(into);
  std::ifstream in(captured);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "WARNING: kept\nWriting is what we do");
}

}  // namespace
}  // namespace ort::test

// Parity on real data, through the user's path: `octomap-rt build ... -o X.ot` must equal
// the map OctoMap's insertPointCloud builds from the same world-frame points, with zero
// differing finest-level voxels and zero differing log-odds.
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include <gtest/gtest.h>
#include <octomap/AbstractOcTree.h>

#include "scene/scan_set.h"
#include "scene/synthetic_scene.h"
#include "support/octomap_reference.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

struct ParityCase {
  std::string data;  // relative to the data folder, or "synthetic"
  double resolution;
  double max_range;
  std::string backend;
};

std::string case_name(const testing::TestParamInfo<ParityCase>& info) {
  const ParityCase& c = info.param;
  std::string n = std::filesystem::path(c.data).stem().string() + "_r" + std::to_string(int(c.resolution * 100)) +
                  "cm_" + (c.max_range < 0 ? std::string("nolimit") : "max" + std::to_string(int(c.max_range))) + "_" +
                  c.backend;
  for (char& ch : n)
    if (!isalnum((unsigned char)ch)) ch = '_';
  return n;
}

class CliParity : public testing::TestWithParam<ParityCase> {};

TEST_P(CliParity, BuildEqualsOctomapInsertPointCloud) {
  const ParityCase& c = GetParam();
  ScanSet set;
  std::string input = "synthetic";
  if (c.data == "synthetic") {
    set = make_synthetic_rooms();
  } else {
    input = data_file(c.data);
    ASSERT_FALSE(input.empty());
    set = load_scan_graph(input);
  }
  const std::string out = testing::TempDir() + "/parity_" + case_name({c, 0}) + ".ot";
  const std::string cmd = std::string(OCTOMAP_RT_CLI) + " build " + input + " -q -r " + std::to_string(c.resolution) +
                          " --max-range " + std::to_string(c.max_range) + " --backend " + c.backend +
                          " --traversal octomap -o " + out + " > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;

  std::unique_ptr<octomap::AbstractOcTree> loaded(octomap::AbstractOcTree::read(out));
  auto* ours = dynamic_cast<octomap::OcTree*>(loaded.get());
  ASSERT_NE(ours, nullptr) << "could not read " << out;
  const auto reference = octomap_reference(set, c.resolution, c.max_range);
  const TreeDiff d = compare_leaves(*ours, *reference);
  EXPECT_EQ(d.differing_voxels, 0u) << d.first_difference;
  EXPECT_EQ(d.differing_logodds, 0u) << d.first_difference;
  EXPECT_GT(d.leaves_a, 1000u);  // a real map, not an empty one
  EXPECT_EQ(compare_structure(*ours, *reference), "");
  std::filesystem::remove(out);
}

std::vector<ParityCase> cases() {
  std::vector<ParityCase> v;
  std::vector<std::string> backends = {"cpu"};
  if (const char* b = std::getenv("OCTOMAP_RT_TEST_BACKENDS")) {
    backends.clear();
    std::string s = b;
    for (size_t p = 0; p != std::string::npos;) {
      const size_t q = s.find(',', p);
      backends.push_back(s.substr(p, q == std::string::npos ? q : q - p));
      p = q == std::string::npos ? q : q + 1;
    }
  } else {
    backends.push_back("cpu-grid");
    backends.push_back("vulkan");
  }
  for (const std::string& b : backends) {
    for (double mr : {-1.0, 10.0}) {
      v.push_back({"3dtk_dat/3dtk_3scans.graph", 0.1, mr, b});
      v.push_back({"3dtk_dat/3dtk_3scans.graph", 0.2, mr, b});
      v.push_back({"octomap_share/scan_dat.graph", 0.1, mr, b});
    }
    v.push_back({"synthetic", 0.1, -1.0, b});
  }
  return v;
}

INSTANTIATE_TEST_SUITE_P(RealData, CliParity, testing::ValuesIn(cases()), case_name);

}  // namespace
}  // namespace ort::test

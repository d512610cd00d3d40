// The status's leaf count on a saved map: OctoMap's getNumLeafNodes, 15 calls, median/min/max.
//   g++ -O2 leaf_walk.cpp -loctomap -loctomath -o leaf_walk && LD_PRELOAD=libjemalloc.so.2 ./leaf_walk MAP.ot
#include <octomap/AbstractOcTree.h>
#include <octomap/OcTree.h>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>
int main(int argc, char** argv) {
  auto* t = dynamic_cast<octomap::OcTree*>(octomap::AbstractOcTree::read(argv[1]));
  std::vector<double> v;
  size_t n = 0;
  for (int i = 0; i < 15; ++i) {
    auto t0 = std::chrono::steady_clock::now();
    n = t->getNumLeafNodes();
    v.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(v.begin(), v.end());
  std::printf("%zu nodes, %zu leaves: getNumLeafNodes median %.2f ms, min %.2f, max %.2f\n", t->size(), n, v[7], v[0],
              v[14]);
}

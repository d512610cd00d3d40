#include <chrono>
#include <cstdio>
#include <cstdlib>
#include "octree/worker_pool.h"
int main(int argc, char** argv) {
  unsigned t = std::atoi(argv[1]);
  ort::WorkerPool pool(t);
  for (int r = 0; r < 3; ++r) {
    const int jobs = 5000;
    auto s = std::chrono::steady_clock::now();
    for (int j = 0; j < jobs; ++j) pool.run([](unsigned) {});
    double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - s).count() / jobs;
    std::printf("%u threads: %.2f us per empty job\n", t, us);
  }
}

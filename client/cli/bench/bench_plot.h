// `octomap-rt bench` charts: a stacked stage-time bar per mapper, grouped by resolution, one
// PNG per data set, log scale (the paper's Fig. 6), drawn with gnuplot.
#pragma once

#include <string>
#include <vector>

#include "cli/bench/bench_results.h"

namespace ort::bench {

// Writes <dir>/<data set>.dat and .gp and runs gnuplot on each, giving <dir>/<data set>.png.
// Returns false (with the reason in `message`) when gnuplot is missing or fails; the data
// and scripts are still written, to be plotted elsewhere.
bool plot_stage_charts(const std::vector<BenchRow>& rows, const std::string& dir, std::string& message);

}  // namespace ort::bench

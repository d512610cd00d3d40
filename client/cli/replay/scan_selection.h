// Which scans of a data set one producer publishes, and in which order: a window
// (--first/--count), a share of a split (--part i/n: index % n == i, so n producers together
// publish every scan once), repeated (--repeat) to make longer runs from small data sets.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace ort::cli {

struct ScanSelection {
  size_t first = 0;
  size_t count = 0;   // 0: all from `first`
  size_t part = 0;    // this producer's share ...
  size_t parts = 1;   // ... of this many
  size_t repeat = 1;  // the whole selection this many times
};

// Parses "i/n" (0 <= i < n). Returns "" or the reason.
std::string parse_part(const std::string& text, ScanSelection& sel);

// Indices into a set of `n` scans, in publishing order. The split is applied to the window,
// so --first/--count/--part compose: window first, then every n-th scan of it.
std::vector<size_t> select_scans(size_t n, const ScanSelection& sel);

}  // namespace ort::cli

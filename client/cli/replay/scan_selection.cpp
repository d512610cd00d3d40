#include "cli/replay/scan_selection.h"

#include <algorithm>
#include <cstdio>

namespace ort::cli {

std::string parse_part(const std::string& text, ScanSelection& sel) {
  size_t i = 0, n = 0;
  int used = 0;
  if (std::sscanf(text.c_str(), "%zu/%zu%n", &i, &n, &used) != 2 || used != static_cast<int>(text.size()))
    return "--part wants i/n, e.g. 0/3: " + text;
  if (n == 0 || i >= n) return "--part i/n needs 0 <= i < n: " + text;
  sel.part = i;
  sel.parts = n;
  return "";
}

std::vector<size_t> select_scans(size_t n, const ScanSelection& sel) {
  std::vector<size_t> window;
  const size_t end = sel.count == 0 ? n : std::min(n, sel.first + sel.count);
  for (size_t i = sel.first; i < end; ++i) {
    if ((i - sel.first) % sel.parts == sel.part) window.push_back(i);
  }
  std::vector<size_t> out;
  out.reserve(window.size() * sel.repeat);
  for (size_t r = 0; r < sel.repeat; ++r) out.insert(out.end(), window.begin(), window.end());
  return out;
}

}  // namespace ort::cli

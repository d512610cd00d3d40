#include "daemon/map/applied_order.h"

#include <sstream>
#include <stdexcept>

namespace ort::daemon {

AppliedOrder::AppliedOrder(std::vector<AppliedEntry> previous) : entries_(std::move(previous)) {}

void AppliedOrder::open_live_log(const std::string& path) {
  std::lock_guard lock(mutex_);
  live_.open(path, std::ios::out | std::ios::app);
  if (!live_) throw std::runtime_error("cannot open applied-order log '" + path + "'");
  live_ << "# octomap-rt applied order v1\n# columns: index robot_id seq utime\n";
  live_.flush();
}

void AppliedOrder::append(const AppliedEntry& e) {
  std::lock_guard lock(mutex_);
  if (live_.is_open()) {
    live_ << format_applied_line(entries_.size(), e);
    live_.flush();
  }
  entries_.push_back(e);
}

void AppliedOrder::restore(std::vector<AppliedEntry> previous) {
  std::lock_guard lock(mutex_);
  entries_ = std::move(previous);
}

size_t AppliedOrder::size() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

std::vector<AppliedEntry> AppliedOrder::entries(size_t n) const {
  std::lock_guard lock(mutex_);
  if (n >= entries_.size()) return entries_;
  return {entries_.begin(), entries_.begin() + static_cast<std::ptrdiff_t>(n)};
}

std::string format_applied_line(size_t index, const AppliedEntry& e) {
  return std::to_string(index) + " " + e.robot_id + " " + std::to_string(e.seq) + " " + std::to_string(e.utime) + "\n";
}

std::string format_applied_order(const std::vector<AppliedEntry>& entries, uint64_t map_bytes) {
  std::string out = "# octomap-rt applied order v1\n# columns: index robot_id seq utime\n";
  out += "# scans " + std::to_string(entries.size()) + "\n";
  out += "# map_bytes " + std::to_string(map_bytes) + "\n";
  for (size_t i = 0; i < entries.size(); ++i) out += format_applied_line(i, entries[i]);
  return out;
}

AppliedOrderFile parse_applied_order(std::istream& in) {
  AppliedOrderFile f;
  std::string line;
  size_t line_no = 0;
  int64_t declared = -1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty()) continue;
    std::istringstream ls(line);
    if (line[0] == '#') {
      std::string hash, key;
      ls >> hash >> key;
      if (key == "scans") ls >> declared;
      if (key == "map_bytes") ls >> f.map_bytes;
      continue;
    }
    size_t index = 0;
    AppliedEntry e;
    if (!(ls >> index >> e.robot_id >> e.seq >> e.utime) || index != f.entries.size())
      throw std::runtime_error("applied order: bad line " + std::to_string(line_no) + ": '" + line + "'");
    f.entries.push_back(std::move(e));
  }
  if (declared >= 0 && static_cast<size_t>(declared) != f.entries.size())
    throw std::runtime_error("applied order: header says " + std::to_string(declared) + " scans, file has " +
                             std::to_string(f.entries.size()));
  return f;
}

AppliedOrderFile read_applied_order(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open '" + path + "'");
  return parse_applied_order(in);
}

}  // namespace ort::daemon

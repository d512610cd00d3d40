// The order in which the server applied scans: (robot, seq) per scan, across producers.
// The map after N scans equals MapEngine applied to the same scans in exactly this order,
// so this is what a reference build needs.
//
// File format (text, one scan per line; FILE.ot.order next to the map, and the optional
// live --applied-log, which has the same body lines but no "# scans"/"# map_bytes"):
//   # octomap-rt applied order v1
//   # columns: index robot_id seq utime
//   # scans <N>
//   # map_bytes <size of the .ot file this order belongs to>
//   0 husky1 0 1700000000000000
//   1 husky2 0 1700000000050000
//   ...
// index counts from 0 over the map's whole life (a restarted server continues it).
#pragma once

#include <cstdint>
#include <fstream>
#include <istream>
#include <mutex>
#include <string>
#include <vector>

namespace ort::daemon {

struct AppliedEntry {
  std::string robot_id;
  int64_t seq = 0;
  int64_t utime = 0;
  bool operator==(const AppliedEntry&) const = default;
};

class AppliedOrder {
 public:
  explicit AppliedOrder(std::vector<AppliedEntry> previous = {});
  // Also append each entry to `path` as it is applied (flushed per line). Throws on failure.
  void open_live_log(const std::string& path);
  void append(const AppliedEntry& e);
  // Replaces the entries (a loaded map's earlier scans).
  void restore(std::vector<AppliedEntry> previous);
  size_t size() const;
  // The first n entries (all when n exceeds the size).
  std::vector<AppliedEntry> entries(size_t n = SIZE_MAX) const;

 private:
  mutable std::mutex mutex_;
  std::vector<AppliedEntry> entries_;
  std::ofstream live_;
};

std::string format_applied_order(const std::vector<AppliedEntry>& entries, uint64_t map_bytes);
std::string format_applied_line(size_t index, const AppliedEntry& e);

struct AppliedOrderFile {
  std::vector<AppliedEntry> entries;
  int64_t map_bytes = -1;  // -1: not recorded (a live log)
};
// Parses either form; throws std::runtime_error naming the bad line.
AppliedOrderFile parse_applied_order(std::istream& in);
AppliedOrderFile read_applied_order(const std::string& path);

}  // namespace ort::daemon

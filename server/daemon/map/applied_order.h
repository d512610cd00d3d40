// The order in which the server applied scans: (robot, seq) per scan, across producers.
// The map after N scans equals MapEngine applied to the same scans in exactly this order,
// so this is what a reference build needs.
//
// File format (text, one scan per line; FILE.ot.order next to the map, and the optional
// live --applied-log, which has the same lines):
//   # octomap-rt applied order v2
//   # columns: index robot_id seq utime
//   0 husky1 0 1700000000000000
//   1 husky2 0 1700000000050000
//   ...
// index counts from 0 over the map's whole life (a restarted server continues it).
//
// The order file is only ever appended to, as scans are applied (stage 2 writes a line into
// a buffer; sync() writes and fsyncs it), and nothing of it is kept in memory but the count:
// a map that lives for millions of scans costs no memory for them and no rewrite at each
// save. Which lines belong to a saved map is in the map's identity file (order_entries); at
// the next start the lines after those (scans a crash lost from the map) are cut off. An
// older server's v1 file ("# scans N", "# map_bytes M" in its header, rewritten whole at
// each save) is read as well, and rewritten once as v2 when opened.
#pragma once

#include <cstdint>
#include <deque>
#include <fstream>
#include <istream>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
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
  AppliedOrder() = default;
  ~AppliedOrder();
  AppliedOrder(const AppliedOrder&) = delete;
  AppliedOrder& operator=(const AppliedOrder&) = delete;

  // Opens (or creates) the order file beside a map; `keep`: how many of its entries belong
  // to the loaded map (the rest is cut off), nullopt: all. Returns the entries kept; with
  // `newest`, also each robot's (id as written) newest kept entry and how many entries the
  // order had with it. Throws std::runtime_error naming the file and why.
  uint64_t open_file(const std::string& path, std::optional<uint64_t> keep,
                     std::map<std::string, std::pair<AppliedEntry, uint64_t>>* newest = nullptr);
  // Also append each entry to `path` as it is applied (flushed per line). Throws on failure.
  void open_live_log(const std::string& path);
  void append(const AppliedEntry& e);
  // Every entry appended so far is written and fsynced. Throws std::runtime_error.
  void sync();
  uint64_t size() const;
  // The newest entries, at most kRecent of them (a bounded window, for a server without an
  // order file and its tests); all of them while size() <= kRecent.
  static constexpr size_t kRecent = 65'536;
  std::vector<AppliedEntry> recent() const;

 private:
  void write_buffer();  // under mutex_
  mutable std::mutex mutex_;
  uint64_t count_ = 0;
  int fd_ = -1;
  std::string path_, buffer_;
  std::deque<AppliedEntry> recent_;
  std::ofstream live_;
};

std::string format_applied_line(size_t index, const AppliedEntry& e);

struct AppliedOrderFile {
  std::vector<AppliedEntry> entries;
  int64_t map_bytes = -1;  // v1 files only; -1: not recorded
};
// Parses either form; throws std::runtime_error naming the bad line.
AppliedOrderFile parse_applied_order(std::istream& in);
AppliedOrderFile read_applied_order(const std::string& path);

}  // namespace ort::daemon

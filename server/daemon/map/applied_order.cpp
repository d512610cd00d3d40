#include "daemon/map/applied_order.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace ort::daemon {
namespace {

constexpr const char* kHeader = "# octomap-rt applied order v2\n# columns: index robot_id seq utime\n";
constexpr size_t kBufferBytes = 64 << 10;

std::runtime_error file_error(const std::string& what, const std::string& path) {
  return std::runtime_error(what + " '" + path + "': " + std::strerror(errno));
}

void write_all(int fd, const std::string& bytes, const std::string& path) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw file_error("cannot write the applied order", path);
    done += static_cast<size_t>(n);
  }
}

}  // namespace

AppliedOrder::~AppliedOrder() {
  try {
    std::lock_guard lock(mutex_);
    write_buffer();
  } catch (const std::exception&) {}
  if (fd_ >= 0) ::close(fd_);
}

uint64_t AppliedOrder::open_file(const std::string& path, std::optional<uint64_t> keep,
                                 std::map<std::string, std::pair<AppliedEntry, uint64_t>>* newest) {
  std::lock_guard lock(mutex_);
  path_ = path;
  uint64_t entries = 0;
  bool v1 = false;
  std::streamoff cut = -1;
  if (std::filesystem::exists(path)) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw file_error("cannot open", path);
    std::string line;
    size_t line_no = 0;
    std::streamoff offset = 0;
    while (std::getline(in, line)) {
      ++line_no;
      const std::streamoff next = offset + static_cast<std::streamoff>(line.size()) + 1;  // getline ate the newline
      if (line.rfind("# scans ", 0) == 0 || line.rfind("# map_bytes ", 0) == 0) v1 = true;
      if (!line.empty() && line[0] != '#') {
        if (keep && entries == *keep) {
          cut = offset;
          break;
        }
        std::istringstream ls(line);
        size_t index = 0;
        AppliedEntry e;
        if (!(ls >> index >> e.robot_id >> e.seq >> e.utime) || index != entries)
          throw std::runtime_error("applied order '" + path + "': bad line " + std::to_string(line_no) + ": '" + line +
                                   "'");
        ++entries;
        if (newest) (*newest)[e.robot_id] = {e, entries};
      }
      offset = next;
    }
  }
  if (v1) {  // rewritten once as v2 (the header without a count, the same entries)
    AppliedOrderFile old = read_applied_order(path);
    if (keep && old.entries.size() > *keep) old.entries.resize(*keep);
    std::string text = kHeader;
    for (size_t i = 0; i < old.entries.size(); ++i) text += format_applied_line(i, old.entries[i]);
    const std::string tmp = path + ".tmp";
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw file_error("cannot create", tmp);
    write_all(fd, text, tmp);
    ::fsync(fd);
    ::close(fd);
    if (::rename(tmp.c_str(), path.c_str()) != 0) throw file_error("cannot rename over", path);
    entries = old.entries.size();
    cut = -1;
  }
  const bool fresh = !std::filesystem::exists(path);
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw file_error("cannot open", path);
  if (cut >= 0 && ::ftruncate(fd_, cut) != 0) throw file_error("cannot cut", path);
  if (::lseek(fd_, 0, SEEK_END) < 0) throw file_error("cannot seek in", path);
  if (fresh) buffer_ = kHeader;
  count_ = entries;
  return entries;
}

void AppliedOrder::open_live_log(const std::string& path) {
  std::lock_guard lock(mutex_);
  live_.open(path, std::ios::out | std::ios::app);
  if (!live_) throw std::runtime_error("cannot open applied-order log '" + path + "'");
  live_ << kHeader;
  live_.flush();
}

void AppliedOrder::append(const AppliedEntry& e) {
  std::lock_guard lock(mutex_);
  const std::string line = format_applied_line(count_, e);
  if (live_.is_open()) {
    live_ << line;
    live_.flush();
  }
  if (fd_ >= 0) {
    buffer_ += line;
    // Written in large pieces; a failure here (disk full) is left for sync() to report.
    if (buffer_.size() >= kBufferBytes) try {
        write_buffer();
      } catch (const std::exception&) {}
  }
  recent_.push_back(e);
  if (recent_.size() > kRecent) recent_.pop_front();
  count_++;
}

std::vector<AppliedEntry> AppliedOrder::recent() const {
  std::lock_guard lock(mutex_);
  return {recent_.begin(), recent_.end()};
}

void AppliedOrder::write_buffer() {
  if (fd_ < 0 || buffer_.empty()) return;
  write_all(fd_, buffer_, path_);
  buffer_.clear();
}

void AppliedOrder::sync() {
  std::lock_guard lock(mutex_);
  if (fd_ < 0) return;
  write_buffer();
  if (::fdatasync(fd_) != 0) throw file_error("cannot fsync", path_);
}

uint64_t AppliedOrder::size() const {
  std::lock_guard lock(mutex_);
  return count_;
}

std::string format_applied_line(size_t index, const AppliedEntry& e) {
  return std::to_string(index) + " " + e.robot_id + " " + std::to_string(e.seq) + " " + std::to_string(e.utime) + "\n";
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

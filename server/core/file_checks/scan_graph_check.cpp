#include "core/file_checks/scan_graph_check.h"

#include <cfloat>
#include <cmath>
#include <cstring>
#include <unordered_set>

namespace ort {
namespace {

constexpr size_t kVector3Bytes = 4 + 3 * 8;
constexpr size_t kQuaternionBytes = 4 + 4 * 8;
constexpr size_t kPoseBytes = kVector3Bytes + kQuaternionBytes;
constexpr size_t kMinScanBytes = 4 + kPoseBytes + 4;
constexpr size_t kEdgeBytes = 8 + kPoseBytes + 8;

class Reader {
 public:
  explicit Reader(std::string_view b) : b_(b) {}
  size_t pos() const { return pos_; }
  size_t left() const { return b_.size() - pos_; }
  template <class T>
  bool get(T& v) {
    if (left() < sizeof v) return false;
    std::memcpy(&v, b_.data() + pos_, sizeof v);
    pos_ += sizeof v;
    return true;
  }

 private:
  std::string_view b_;
  size_t pos_ = 0;
};

std::string at(const Reader& r) { return " at byte " + std::to_string(r.pos()); }

// A Vector3 or Quaternion: its element-count marker, then doubles that OctoMap narrows to
// float (a finite double beyond float's range would be undefined there; NaN is kept, the
// engine drops such points and counts them).
std::string check_vector(Reader& r, int32_t marker, const char* what) {
  int32_t n = 0;
  if (!r.get(n)) return std::string("the data ends inside a ") + what + at(r);
  if (n != marker) return std::string("a ") + what + " has the wrong element count " + std::to_string(n) + at(r);
  for (int32_t i = 0; i < marker; ++i) {
    double v = 0;
    if (!r.get(v)) return std::string("the data ends inside a ") + what + at(r);
    if (std::isfinite(v) && std::abs(v) > FLT_MAX)
      return std::string("a ") + what + " value exceeds float's range" + at(r);
  }
  return "";
}

std::string check_pose(Reader& r) {
  if (std::string why = check_vector(r, 3, "position"); !why.empty()) return why;
  return check_vector(r, 4, "rotation");
}

std::string check_scan(Reader& r, uint64_t index, uint64_t& points, std::unordered_set<uint32_t>& ids) {
  const std::string which = "scan " + std::to_string(index);
  uint32_t n = 0;
  if (!r.get(n)) return which + ": the data ends before its point count" + at(r);
  if (n > (r.left() - std::min(r.left(), kPoseBytes + 4)) / kVector3Bytes)
    return which + " claims " + std::to_string(n) + " points but only " + std::to_string(r.left()) + " bytes remain" +
           at(r) + " (file truncated?)";
  for (uint32_t i = 0; i < n; ++i)
    if (std::string why = check_vector(r, 3, "point"); !why.empty()) return which + ": " + why;
  points += n;
  if (std::string why = check_pose(r); !why.empty()) return which + ": " + why;
  uint32_t id = 0;
  if (!r.get(id)) return which + ": the data ends before its id" + at(r);
  ids.insert(id);
  return "";
}

ScanGraphCheck fail(ScanGraphCheck c, std::string why) {
  c.ok = false;
  c.error = std::move(why);
  return c;
}

}  // namespace

ScanGraphCheck check_scan_graph(std::string_view bytes) {
  ScanGraphCheck c;
  Reader r(bytes);
  uint32_t scans = 0;
  if (!r.get(scans)) return fail(c, "too short for a ScanGraph (" + std::to_string(bytes.size()) + " bytes)");
  if (scans > r.left() / kMinScanBytes)
    return fail(c, "the header claims " + std::to_string(scans) + " scans but " + std::to_string(r.left()) +
                       " bytes hold at most " + std::to_string(r.left() / kMinScanBytes) +
                       " (file truncated or not a ScanGraph?)");
  std::unordered_set<uint32_t> ids;
  for (uint32_t i = 0; i < scans; ++i) {
    if (std::string why = check_scan(r, i, c.points, ids); !why.empty()) return fail(c, why);
    c.scans++;
  }
  uint32_t edges = 0;
  if (!r.get(edges)) return fail(c, "the data ends before the edge count" + at(r) + " (file truncated?)");
  if (edges > r.left() / kEdgeBytes)
    return fail(c, "the file claims " + std::to_string(edges) + " edges but " + std::to_string(r.left()) +
                       " bytes hold at most " + std::to_string(r.left() / kEdgeBytes) + " (file truncated?)");
  for (uint32_t i = 0; i < edges; ++i) {
    uint32_t first = 0, second = 0;
    r.get(first);
    r.get(second);
    if (!ids.count(first) || !ids.count(second))
      return fail(c, "edge " + std::to_string(i) + " names a scan id that no scan has" + at(r));
    if (std::string why = check_pose(r); !why.empty()) return fail(c, "edge " + std::to_string(i) + ": " + why);
    double weight = 0;
    r.get(weight);
    c.edges++;
  }
  if (r.left() != 0) return fail(c, std::to_string(r.left()) + " bytes follow the last edge" + at(r));
  c.ok = true;
  return c;
}

}  // namespace ort

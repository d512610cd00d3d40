#include "octree/leaf_changes.h"

#include <algorithm>

namespace ort {

void LeafChanges::reset(unsigned lanes) {
  if (lanes_.size() < lanes) {
    lanes_.resize(lanes);
    lane_segments_.resize(lanes);
  }
  for (auto& l : lanes_) l.clear();
  for (auto& s : lane_segments_) s.clear();
  segments_.clear();
}

void LeafChanges::close_segment(unsigned lane, size_t order) {
  std::vector<Segment>& segs = lane_segments_[lane];
  const size_t begin = segs.empty() ? 0 : segs.back().end;
  const size_t end = lanes_[lane].size();
  if (end > begin) segs.push_back(Segment{order, lane, begin, end});
}

void LeafChanges::finish() {
  segments_.clear();
  for (auto& segs : lane_segments_) {
    segments_.insert(segments_.end(), segs.begin(), segs.end());
    segs.clear();
  }
  std::sort(segments_.begin(), segments_.end(), [](const Segment& a, const Segment& b) {
    return a.order != b.order ? a.order < b.order : a.begin < b.begin;
  });
}

size_t LeafChanges::size() const {
  size_t n = 0;
  for (const Segment& s : segments_) n += s.end - s.begin;
  return n;
}

std::vector<LeafChange> LeafChanges::to_vector() const {
  std::vector<LeafChange> out;
  out.reserve(size());
  for_each([&](const LeafChange& c) { out.push_back(c); });
  return out;
}

}  // namespace ort

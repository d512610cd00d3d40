#include "gpu/gpu_test_support.h"

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <unordered_map>

#include <octomap/OcTree.h>

#include "core/exact_traversal.h"
#include "engine/backend_factory.h"

namespace ort::test {
namespace {

uint64_t pack(const VoxelUpdate& v) { return (uint64_t(v.z) << 32) | (uint64_t(v.y) << 16) | v.x; }

// The free keys of one ray by the reference, and its occupied end key if any.
void reference_ray(const octomap::OcTree& keys, const RayBatch& batch, const RayEnd& e, Traversal mode,
                   std::vector<octomap::OcTreeKey>& free_keys, bool& occupied, octomap::OcTreeKey& end_key) {
  const octomap::point3d end(e.x, e.y, e.z);
  free_keys.clear();
  if (mode == Traversal::kOctomap) {
    octomap::KeyRay ray;
    if (keys.computeRayKeys(batch.origin, end, ray)) free_keys.assign(ray.begin(), ray.end());
  } else {
    exact_ray_keys(batch.origin, end, batch.resolution, free_keys);
  }
  occupied = (e.flags & kRayEndOccupied) && keys.coordToKeyChecked(end, end_key);
}

}  // namespace

std::unique_ptr<RayBackend> make_vulkan(double resolution, double max_range, uint64_t grid_budget_bytes) {
  BackendOptions o;
  o.kind = BackendKind::kVulkan;
  o.resolution = resolution;
  o.max_range = max_range;
  o.grid_budget_bytes = grid_budget_bytes;
  if (const char* d = std::getenv("OCTOMAP_RT_TEST_DEVICE")) o.device = d;
  return make_backend(o);
}

VoxelList reference_states(const RayBatch& batch, Traversal mode) {
  const octomap::OcTree keys(batch.resolution);
  std::unordered_map<uint64_t, VoxelUpdate> states;
  std::vector<octomap::OcTreeKey> free_keys;
  std::vector<octomap::OcTreeKey> occupied_keys;
  for (const RayEnd& e : batch.ends) {
    bool occupied = false;
    octomap::OcTreeKey end_key;
    reference_ray(keys, batch, e, mode, free_keys, occupied, end_key);
    for (const auto& k : free_keys) {
      const VoxelUpdate v = make_update(k, false);
      states.emplace(pack(v), v);
    }
    if (occupied) occupied_keys.push_back(end_key);
  }
  for (const auto& k : occupied_keys) {
    const VoxelUpdate v = make_update(k, true);
    states[pack(v)] = v;  // occupied wins
  }
  VoxelList out;
  out.reserve(states.size());
  for (const auto& [key, v] : states) out.push_back(v);
  sort_voxels(out);
  return out;
}

void sort_voxels(VoxelList& v) {
  std::sort(v.begin(), v.end(), [](const VoxelUpdate& a, const VoxelUpdate& b) { return pack(a) < pack(b); });
}

bool same_voxels(const VoxelList& a, const VoxelList& b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](const VoxelUpdate& x, const VoxelUpdate& y) {
           return pack(x) == pack(y) && x.state == y.state;
         });
}

std::string diff_voxels(const VoxelList& got, const VoxelList& want, const RayBatch& batch, Traversal mode) {
  std::unordered_map<uint64_t, uint16_t> g, w;
  for (const VoxelUpdate& v : got) {
    if (!g.emplace(pack(v), v.state).second) return "a key was returned twice";
  }
  for (const VoxelUpdate& v : want) w.emplace(pack(v), v.state);
  std::vector<std::pair<uint64_t, std::string>> bad;
  for (const auto& [k, s] : g) {
    auto it = w.find(k);
    if (it == w.end())
      bad.push_back({k, "extra (state " + std::to_string(s) + ")"});
    else if (it->second != s)
      bad.push_back({k, "state " + std::to_string(s) + " instead of " + std::to_string(it->second)});
  }
  for (const auto& [k, s] : w) {
    if (!g.count(k)) bad.push_back({k, "missing (state " + std::to_string(s) + ")"});
  }
  if (bad.empty()) return "";
  std::sort(bad.begin(), bad.end());
  std::ostringstream os;
  os.precision(9);
  os << bad.size() << " differing voxels; origin (" << batch.origin.x() << ", " << batch.origin.y() << ", "
     << batch.origin.z() << "), resolution " << batch.resolution << ", " << batch.ends.size() << " rays";
  const octomap::OcTree keys(batch.resolution);
  std::vector<octomap::OcTreeKey> free_keys;
  for (size_t i = 0; i < std::min<size_t>(bad.size(), 5); ++i) {
    const uint64_t k = bad[i].first;
    os << "\n  key (" << (k & 0xFFFF) << ", " << ((k >> 16) & 0xFFFF) << ", " << (k >> 32) << "): " << bad[i].second;
    // Name the rays that reach this key by the reference (or all rays, if none does).
    for (size_t r = 0; r < batch.ends.size(); ++r) {
      bool occupied = false;
      octomap::OcTreeKey end_key;
      reference_ray(keys, batch, batch.ends[r], mode, free_keys, occupied, end_key);
      bool has = false;
      for (const auto& fk : free_keys) has |= (pack(make_update(fk, false)) == k);
      has |= occupied && pack(make_update(end_key, true)) == k;
      if (has || batch.ends.size() <= 2) {
        os << "\n    ray " << r << " -> (" << batch.ends[r].x << ", " << batch.ends[r].y << ", " << batch.ends[r].z
           << ") flags " << batch.ends[r].flags;
      }
    }
  }
  return os.str();
}

}  // namespace ort::test

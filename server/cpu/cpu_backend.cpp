#include "cpu/cpu_backend.h"

#include <chrono>

#include <octomap/OcTree.h>

#include "core/clock.h"
#include "core/exact_traversal.h"

namespace ort {
namespace {

class CpuBackend final : public RayBackend {
 public:
  explicit CpuBackend(double resolution) : key_tree_(resolution) {}
  BackendKind kind() const override { return BackendKind::kCpu; }
  std::string device_name() const override { return "CPU (OctoMap computeRayKeys)"; }

  void shoot(const RayBatch& batch, Traversal mode, VoxelList& out, ShootStats& stats) override {
    const auto t0 = SteadyClock::now();
    octomap::KeySet free_cells, occupied_cells;
    octomap::KeyRay ray;
    std::vector<octomap::OcTreeKey> exact;
    for (const RayEnd& e : batch.ends) {
      const octomap::point3d end(e.x, e.y, e.z);
      if (mode == Traversal::kOctomap) {
        if (key_tree_.computeRayKeys(batch.origin, end, ray)) free_cells.insert(ray.begin(), ray.end());
      } else {
        exact.clear();
        exact_ray_keys(batch.origin, end, batch.resolution, exact);
        free_cells.insert(exact.begin(), exact.end());
      }
      if (e.flags & kRayEndOccupied) {
        octomap::OcTreeKey key;
        if (key_tree_.coordToKeyChecked(end, key)) occupied_cells.insert(key);
      }
    }
    out.clear();
    out.reserve(free_cells.size() + occupied_cells.size());
    for (const auto& k : free_cells) {
      if (!occupied_cells.count(k)) out.push_back(make_update(k, false));
    }
    for (const auto& k : occupied_cells) out.push_back(make_update(k, true));
    stats.windows = 1;
    stats.times.shoot_ms += ms_since(t0);
  }

 private:
  octomap::OcTree key_tree_;  // only for its key arithmetic (resolution)
};

}  // namespace

std::unique_ptr<RayBackend> make_cpu_backend(double resolution) { return std::make_unique<CpuBackend>(resolution); }

}  // namespace ort

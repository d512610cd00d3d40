#include "daemon/distance_backend.h"

#include <algorithm>
#include <stdexcept>

#include "core/errors.h"
#include "engine/distance_device.h"

namespace ort::daemon {

DistanceBackend choose_distance_backend(const std::string& backend, const std::string& device_name, int threads_asked) {
  if (backend != "cpu" && backend != "vulkan" && backend != "auto")
    throw std::invalid_argument("--distance-backend must be cpu, vulkan or auto, not '" + backend + "'");
  if (backend != "cpu") {
    try {
      EdtDevice device = open_edt_device(device_name);
      if (backend == "vulkan" || !device.cpu_implementation) {
        DeviceEdt run = std::move(device.run);
        return {[run](std::span<const uint8_t> occ, distance::GridDims g, std::span<uint32_t> out) {
                  run(occ, g.nx, g.ny, g.nz, out);
                },
                "vulkan (" + device.name + ")"};
      }
    } catch (const Unsupported&) {
      if (backend == "vulkan") throw;
    }
  }
  const int threads = std::max(1, threads_asked);
  return {distance::cpu_edt(threads), "cpu (" + std::to_string(threads) + " threads)"};
}

}  // namespace ort::daemon

#include "engine/distance_device.h"

#include "gpu/distance_transform.h"

namespace ort {

EdtDevice open_edt_device(const std::string& device) {
  auto gpu = std::make_shared<gpu::DistanceTransform>(device);
  EdtDevice d;
  d.name = gpu->device_name();
  d.cpu_implementation = gpu->on_cpu_device();
  d.run = [gpu](std::span<const uint8_t> occupied, int nx, int ny, int nz, std::span<uint32_t> out) {
    gpu->run(occupied, nx, ny, nz, out);
  };
  return d;
}

}  // namespace ort

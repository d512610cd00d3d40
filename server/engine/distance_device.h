// The Vulkan device that distance queries may run their EDT on (gpu/distance_transform.h),
// chosen here beside the mapping back ends, so the daemon picks one without reaching into
// gpu/: it sees a function on a dense grid and a name.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>

namespace ort {

// out[i] = squared distance (cell units) of cell i = x + nx * (y + ny * z) to the nearest
// occupied cell (0xFFFFFFFF without any): gpu::DistanceTransform::run.
using DeviceEdt =
    std::function<void(std::span<const uint8_t> occupied, int nx, int ny, int nz, std::span<uint32_t> out)>;

struct EdtDevice {
  DeviceEdt run;  // one caller at a time (the device's queue and buffers are its own)
  std::string name;
  bool cpu_implementation = false;  // lavapipe: CPU threads are the better choice there
};

// `device`: an index or a name substring, "" automatic. Throws ort::Unsupported (core/errors.h)
// where there is no usable Vulkan device.
EdtDevice open_edt_device(const std::string& device);

}  // namespace ort

// Where the query service's distance transforms run (--distance-backend): CPU threads or the
// Vulkan device, chosen once at start.
#pragma once

#include <string>

#include "distance/squared_edt.h"

namespace ort::daemon {

struct DistanceBackend {
  distance::SquaredEdt edt;
  std::string name;  // "cpu (N threads)" or "vulkan (DEVICE)"
};

// cpu: CPU threads. vulkan: the device, or std::invalid_argument / Unsupported (the server does
// not start). auto: the device where it is a GPU (not a CPU implementation such as lavapipe),
// else CPU threads. Throws std::invalid_argument for another backend name.
// `device`: a Vulkan device (index or name substring), "" automatic; `threads`: CPU EDT workers.
DistanceBackend choose_distance_backend(const std::string& backend, const std::string& device, int threads);

}  // namespace ort::daemon

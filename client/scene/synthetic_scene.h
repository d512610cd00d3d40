// The built-in synthetic scene: a few rooms seen by a simulated range sensor from several
// poses. Deterministic, needs no data files; `octomap-rt build synthetic` and the demo use it.
#pragma once

#include "scene/scan_set.h"

namespace ort {

ScanSet make_synthetic_rooms();

}  // namespace ort

// Height to colour: a rainbow-like ramp from dark blue (low) through green to red (high),
// the convention of octovis' height colouring, with a perceptually smoother path.
#pragma once

#include "render/canvas.h"

namespace ort::render {

class HeightColours {
 public:
  HeightColours(double z_low, double z_high) : low_(z_low), high_(z_high > z_low ? z_high : z_low + 1e-9) {}
  Rgb at(double z) const;  // clamped to [low, high]
  double low() const { return low_; }
  double high() const { return high_; }

 private:
  double low_, high_;
};

}  // namespace ort::render

#include "render/height_colours.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace ort::render {
namespace {

// Stops of Google's "turbo" map, sampled evenly (inner stops only: its near-black ends are
// hard to tell from the outlines).
constexpr std::array<Rgb, 7> kStops{
    {{48, 18, 59}, {70, 107, 227}, {41, 187, 236}, {49, 241, 150}, {164, 252, 60}, {250, 186, 57}, {213, 53, 7}}};

uint8_t mix(uint8_t a, uint8_t b, double f) { return uint8_t(std::lround(a + (b - a) * f)); }

}  // namespace

Rgb HeightColours::at(double z) const {
  const double t = std::clamp((z - low_) / (high_ - low_), 0.0, 1.0) * (kStops.size() - 1);
  const size_t i = std::min(size_t(t), kStops.size() - 2);
  const double f = t - double(i);
  const Rgb a = kStops[i], b = kStops[i + 1];
  return {mix(a.r, b.r, f), mix(a.g, b.g, f), mix(a.b, b.b, f)};
}

}  // namespace ort::render

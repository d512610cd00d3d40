#include "render/distance_slice.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "render/bitmap_font.h"
#include "render/canvas.h"
#include "render/png_file.h"

namespace ort::render {
namespace {

constexpr Rgb kObstacle{0, 0, 0}, kText{0, 0, 0}, kPaper{255, 255, 255};

// t in [0, 1]: red, yellow, green, cyan, blue.
Rgb ramp(double t) {
  static const Rgb stops[] = {{215, 25, 28}, {253, 174, 97}, {171, 221, 164}, {43, 131, 186}, {30, 60, 140}};
  t = std::clamp(t, 0.0, 1.0) * 4;
  const int i = std::min(3, int(t));
  const double f = t - i;
  auto mix = [&](uint8_t a, uint8_t b) { return uint8_t(std::lround(a + (b - a) * f)); };
  return {mix(stops[i].r, stops[i + 1].r), mix(stops[i].g, stops[i + 1].g), mix(stops[i].b, stops[i + 1].b)};
}

Rgb colour(float d, double max) { return d <= 0 ? kObstacle : ramp(d / max); }

}  // namespace

void write_distance_slice_png(const DistanceSlice& s, const std::string& path, int cell_px) {
  const int w = std::max(1, s.width), h = std::max(1, s.height);
  if (cell_px <= 0) cell_px = std::clamp(800 / w, 1, 16);
  const int margin = 10, footer = 70;
  Canvas c(std::max(w * cell_px + 2 * margin, 420), h * cell_px + 2 * margin + footer, kPaper);
  for (int j = 0; j < s.height; ++j)
    for (int i = 0; i < s.width; ++i) {
      const int x = margin + i * cell_px, y = margin + (s.height - 1 - j) * cell_px;  // +y up
      c.fill_rect(x, y, x + cell_px, y + cell_px, colour(s.distance[size_t(j) * s.width + i], s.max_distance));
    }
  // Colour bar: 0 .. max_distance.
  int y = margin + h * cell_px + 10;
  const int bar_w = 200;
  c.fill_rect(margin, y, margin + 10, y + 12, kObstacle);
  for (int x = 0; x < bar_w; ++x) c.fill_rect(margin + 14 + x, y, margin + 15 + x, y + 12, ramp(double(x) / bar_w));
  char label[128];
  std::snprintf(label, sizeof label, "0 .. %g m (clamp)", s.max_distance);
  draw_text(c, margin + 20 + bar_w, y, label, kText);
  // Scale bar: the largest 1, 2, 5 x 10^k metres under 40 % of the width.
  const double metres_per_px = s.cell_size / cell_px, max_m = 0.4 * (c.width() - 2 * margin) * metres_per_px;
  const double p = std::pow(10.0, std::floor(std::log10(max_m)));
  double bar_m = p;
  for (double f : {5.0, 2.0, 1.0})
    if (f * p <= max_m) {
      bar_m = f * p;
      break;
    }
  y += 24;
  c.fill_rect(margin, y, margin + std::max(1, int(std::lround(bar_m / metres_per_px))), y + 4, kText);
  std::snprintf(label, sizeof label, "%g m  (cell %g m, slice z %.2f m)", bar_m, s.cell_size, s.z);
  draw_text(c, margin, y + 10, label, kText);
  write_png(c, path);
}

}  // namespace ort::render

#include "render/map_legend.h"

#include <cmath>
#include <cstdio>

#include "render/bitmap_font.h"

namespace ort::render {
namespace {

constexpr Rgb kInk{40, 40, 40};
constexpr int kLeft = 12;

std::string metres(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, std::abs(v) < 10 && v != std::round(v) ? "%.2g" : "%.0f", v);
  return buf;
}

std::string range(char axis, double lo, double hi) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%c %.1f..%.1f", axis, lo, hi);
  return buf;
}

// The scale bar with end ticks and its length; returns the x after its label.
int draw_scale_bar(Canvas& canvas, int x, int y, const ViewCamera& camera) {
  const double length = scale_bar_metres(camera.width() / 4.0 / camera.pixels_per_metre());
  const int px = std::max(1, int(std::lround(length * camera.pixels_per_metre())));
  canvas.fill_rect(x, y + 6, x + px, y + 9, kInk);
  canvas.fill_rect(x, y, x + 2, y + 15, kInk);
  canvas.fill_rect(x + px - 2, y, x + px, y + 15, kInk);
  return draw_text(canvas, x + px + 8, y + 1, metres(length) + " m", kInk);
}

// The height ramp between its two end values; returns the x after it.
int draw_colour_ramp(Canvas& canvas, int x, int y, const HeightColours& colours) {
  x = draw_text(canvas, x, y + 1, "z " + metres(colours.low()), kInk) + 6;
  const int w = 160;
  for (int i = 0; i < w; ++i)
    canvas.fill_rect(x + i, y, x + i + 1, y + 15,
                     colours.at(colours.low() + (colours.high() - colours.low()) * (i + 0.5) / w));
  return draw_text(canvas, x + w + 6, y + 1, metres(colours.high()) + " m", kInk);
}

}  // namespace

double scale_bar_metres(double max_metres) {
  if (!(max_metres > 0)) return 1;
  const double decade = std::pow(10.0, std::floor(std::log10(max_metres)));
  for (double step : {5.0, 2.0, 1.0})
    if (step * decade <= max_metres) return step * decade;
  return decade;
}

void draw_legend(Canvas& canvas, int top, const ViewCamera& camera, const HeightColours& colours, const Box3& extent,
                 double resolution) {
  canvas.fill_rect(0, top, canvas.width(), top + 1, Rgb{200, 200, 200});
  const int row1 = top + 10, row2 = top + 36;
  const int after_bar = draw_scale_bar(canvas, kLeft, row1, camera);
  draw_colour_ramp(canvas, after_bar + 40, row1, colours);
  const std::string text = range('x', extent.lo[0], extent.hi[0]) + "  " + range('y', extent.lo[1], extent.hi[1]) +
                           "  " + range('z', extent.lo[2], extent.hi[2]) + " m  (" + metres(resolution) +
                           " m voxels, " + (camera.view() == View::top ? "top" : "oblique") + ")";
  draw_text(canvas, kLeft, row2, text, kInk);
}

}  // namespace ort::render

#include "cli/grid_picture.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "render/bitmap_font.h"
#include "render/canvas.h"
#include "render/png_file.h"

namespace ort::client {
namespace {

using render::Rgb;
constexpr Rgb kFree{235, 235, 235}, kOccupied{30, 30, 30}, kUnknown{120, 150, 200}, kText{0, 0, 0},
    kPaper{255, 255, 255};

Rgb colour(int8_t state) { return state == 2 ? kOccupied : state == 1 ? kFree : kUnknown; }

// The largest 1, 2, 5 x 10^k metres not longer than `max_m`.
double nice_length(double max_m) {
  const double p = std::pow(10.0, std::floor(std::log10(max_m)));
  for (double f : {5.0, 2.0, 1.0})
    if (f * p <= max_m) return f * p;
  return p;
}

}  // namespace

void write_grid_png(const Grid& g, const std::string& path, int cell_px) {
  const int w = std::max(1, g.header.width), h = std::max(1, g.header.height);
  if (cell_px <= 0) cell_px = std::clamp(800 / w, 1, 16);
  const int margin = 10, footer = 60;
  render::Canvas c(w * cell_px + 2 * margin, std::max(h * cell_px + 2 * margin + footer, 140), kPaper);
  const int width = std::max(c.width(), 420);
  if (width != c.width()) c = render::Canvas(width, c.height(), kPaper);
  for (int j = 0; j < g.header.height; ++j)
    for (int i = 0; i < g.header.width; ++i) {
      const int x = margin + i * cell_px, y = margin + (g.header.height - 1 - j) * cell_px;  // +y up
      c.fill_rect(x, y, x + cell_px, y + cell_px, colour(g.cells[size_t(j) * g.header.width + i]));
    }
  // Legend and scale bar under the grid.
  int y = margin + h * cell_px + 12, x = margin;
  for (auto [state, name] : {std::pair<int8_t, const char*>{1, "free"}, {2, "occupied"}, {0, "unknown"}}) {
    c.fill_rect(x, y, x + 14, y + 14, colour(state));
    c.fill_rect(x, y, x + 14, y + 1, kText), c.fill_rect(x, y + 13, x + 14, y + 14, kText);
    c.fill_rect(x, y, x + 1, y + 14, kText), c.fill_rect(x + 13, y, x + 14, y + 14, kText);
    x = render::draw_text(c, x + 20, y, name, kText) + 16;
  }
  const double metres_per_px = g.header.cell_size / cell_px;
  const double bar_m = nice_length(std::max(g.header.cell_size, 0.4 * (c.width() - 2 * margin) * metres_per_px));
  const int bar_px = std::max(1, static_cast<int>(std::lround(bar_m / metres_per_px)));
  y += 26;
  c.fill_rect(margin, y, margin + bar_px, y + 4, kText);
  char label[96];
  std::snprintf(label, sizeof label, "%g m  (cell %g m, z %g..%g m)", bar_m, g.header.cell_size, g.header.z_min,
                g.header.z_max);
  render::draw_text(c, margin, y + 10, label, kText);
  render::write_png(c, path);
}

}  // namespace ort::client

#include "render/canvas.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ort::render {

Rgb scaled(Rgb c, double f) {
  auto one = [f](uint8_t v) { return uint8_t(std::clamp(std::lround(v * f), 0L, 255L)); };
  return {one(c.r), one(c.g), one(c.b)};
}

Canvas::Canvas(int width, int height, Rgb background)
    : width_(width),
      height_(height),
      pixels_(size_t(width) * size_t(height), background),
      depth_(size_t(width) * size_t(height), std::numeric_limits<float>::infinity()) {}

void Canvas::set(int x, int y, Rgb c) {
  if (x >= 0 && y >= 0 && x < width_ && y < height_) pixels_[index(x, y)] = c;
}

void Canvas::fill_rect(int x0, int y0, int x1, int y1, Rgb c) {
  for (int y = std::max(y0, 0); y < std::min(y1, height_); ++y)
    for (int x = std::max(x0, 0); x < std::min(x1, width_); ++x) pixels_[index(x, y)] = c;
}

// Calls plot(x, y, depth, edge_distance_px, min_width_px) for every pixel centre inside the
// parallelogram, with (s, t) its coordinates along v0->v1 and v0->v3; or, when no centre is
// inside, once for the pixel under its centre.
template <class Plot>
void Canvas::raster_face(const std::array<ScreenPoint, 4>& v, Plot&& plot) {
  const double e1x = v[1].x - v[0].x, e1y = v[1].y - v[0].y;
  const double e2x = v[3].x - v[0].x, e2y = v[3].y - v[0].y;
  const double det = e1x * e2y - e1y * e2x;
  if (std::abs(det) < 1e-12) return;  // seen edge-on
  const double len1 = std::hypot(e1x, e1y), len2 = std::hypot(e2x, e2y);
  const double width_s = std::abs(det) / len2, width_t = std::abs(det) / len1;  // pixels across
  const double d0 = v[0].depth, dd1 = v[1].depth - d0, dd2 = v[3].depth - d0;
  double xmin = v[0].x, xmax = v[0].x, ymin = v[0].y, ymax = v[0].y;
  for (const auto& p : v) {
    xmin = std::min(xmin, p.x), xmax = std::max(xmax, p.x);
    ymin = std::min(ymin, p.y), ymax = std::max(ymax, p.y);
  }
  const int x0 = std::max(0, int(std::ceil(xmin - 0.5))), x1 = std::min(width_ - 1, int(std::floor(xmax - 0.5)));
  const int y0 = std::max(0, int(std::ceil(ymin - 0.5))), y1 = std::min(height_ - 1, int(std::floor(ymax - 0.5)));
  bool any = false;
  for (int y = y0; y <= y1; ++y) {
    const double py = y + 0.5 - v[0].y;
    for (int x = x0; x <= x1; ++x) {
      const double px = x + 0.5 - v[0].x;
      const double s = (px * e2y - py * e2x) / det, t = (e1x * py - e1y * px) / det;
      if (s < 0 || s > 1 || t < 0 || t > 1) continue;
      any = true;
      const double edge = std::min(std::min(s, 1 - s) * width_s, std::min(t, 1 - t) * width_t);
      plot(x, y, d0 + s * dd1 + t * dd2, edge, std::min(width_s, width_t));
    }
  }
  if (!any) {
    const double cx = (v[0].x + v[2].x) / 2, cy = (v[0].y + v[2].y) / 2;
    const int x = int(std::floor(cx)), y = int(std::floor(cy));
    if (x >= 0 && y >= 0 && x < width_ && y < height_) plot(x, y, (v[0].depth + v[2].depth) / 2, 1e9, 0.0);
  }
}

void Canvas::fill_face(const std::array<ScreenPoint, 4>& v, Rgb c, double outline_min_px) {
  const Rgb border = scaled(c, 0.72);
  raster_face(v, [&](int x, int y, double depth, double edge, double min_width) {
    const size_t i = index(x, y);
    if (!(depth < depth_[i])) return;
    depth_[i] = float(depth);
    pixels_[i] = (min_width >= outline_min_px && edge < 0.75) ? border : c;
  });
}

void Canvas::paint_face(const std::array<ScreenPoint, 4>& v, Rgb c) {
  raster_face(v, [&](int x, int y, double, double, double) { pixels_[index(x, y)] = c; });
}

}  // namespace ort::render

// An RGB picture with a depth buffer, and the one primitive the map renderer needs: a
// z-buffered parallelogram (an orthographic box face).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "render/view_camera.h"

namespace ort::render {

struct Rgb {
  uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb&) const = default;
};

Rgb scaled(Rgb c, double factor);  // darker (< 1) or brighter (> 1), clamped

class Canvas {
 public:
  Canvas(int width, int height, Rgb background);

  int width() const { return width_; }
  int height() const { return height_; }
  Rgb at(int x, int y) const { return pixels_[index(x, y)]; }
  const std::vector<Rgb>& pixels() const { return pixels_; }
  void set(int x, int y, Rgb c);                          // ignores pixels outside
  void fill_rect(int x0, int y0, int x1, int y1, Rgb c);  // [x0, x1) x [y0, y1)

  // The parallelogram v0 v1 v2 v3 (v2 = v1 + v3 - v0), filled where it is nearer than what
  // is there. A face too small to cover a pixel centre still sets the pixel under its
  // centre, so isolated voxels far smaller than a pixel stay visible. Faces at least
  // `outline_min_px` wide get a darker one-pixel border, so large voxels read as boxes.
  void fill_face(const std::array<ScreenPoint, 4>& v, Rgb c, double outline_min_px = 5);
  // The same area painted without depth (under anything drawn with depth later).
  void paint_face(const std::array<ScreenPoint, 4>& v, Rgb c);

 private:
  size_t index(int x, int y) const { return size_t(y) * size_t(width_) + size_t(x); }
  template <class Plot>
  void raster_face(const std::array<ScreenPoint, 4>& v, Plot&& plot);

  int width_, height_;
  std::vector<Rgb> pixels_;
  std::vector<float> depth_;
};

}  // namespace ort::render

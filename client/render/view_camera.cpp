#include "render/view_camera.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace ort::render {
namespace {

double dot(const std::array<double, 3>& a, double x, double y, double z) { return a[0] * x + a[1] * y + a[2] * z; }

std::array<double, 3> cross(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

}  // namespace

PlaneExtent PlaneExtent::none() {
  const double inf = std::numeric_limits<double>::infinity();
  return {inf, -inf, inf, -inf};
}

ViewCamera ViewCamera::looking(View view, double azimuth_deg, double elevation_deg) {
  ViewCamera cam;
  cam.view_ = view;
  if (view == View::top) {
    cam.right_ = {1, 0, 0};
    cam.up_ = {0, 1, 0};
    cam.back_ = {0, 0, 1};
  } else {
    const double a = azimuth_deg * std::numbers::pi / 180, e = elevation_deg * std::numbers::pi / 180;
    cam.back_ = {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
    cam.right_ = {-std::sin(a), std::cos(a), 0};
    cam.up_ = cross(cam.back_, cam.right_);  // right x up = back: a right-handed screen
  }
  return cam;
}

void ViewCamera::extend(PlaneExtent& e, double x, double y, double z) const {
  const double r = dot(right_, x, y, z), u = dot(up_, x, y, z);
  e.right_lo = std::min(e.right_lo, r), e.right_hi = std::max(e.right_hi, r);
  e.up_lo = std::min(e.up_lo, u), e.up_hi = std::max(e.up_hi, u);
}

void ViewCamera::frame(const PlaneExtent& e, int width, int margin) {
  if (e.empty()) throw std::invalid_argument("nothing to draw: the map has no voxels in the height range");
  if (width <= 2 * margin + 16) throw std::invalid_argument("picture width too small");
  scale_ = (width - 2 * margin) / std::max(e.right_hi - e.right_lo, 1e-6);
  right0_ = e.right_lo;
  up0_ = e.up_hi;
  margin_ = margin;
  width_ = width;
  height_ = int(std::ceil((e.up_hi - e.up_lo) * scale_)) + 2 * margin;
}

ScreenPoint ViewCamera::project(double x, double y, double z) const {
  return {margin_ + (dot(right_, x, y, z) - right0_) * scale_, margin_ + (up0_ - dot(up_, x, y, z)) * scale_,
          -dot(back_, x, y, z)};
}

}  // namespace ort::render

// Orthographic cameras for map pictures: straight down (top) or from above at an angle
// (oblique). Orthographic, so one scale (pixels per metre) holds everywhere in the picture
// for lengths parallel to the image plane, and a scale bar means something.
#pragma once

#include <array>

namespace ort::render {

enum class View { top, oblique };

struct ScreenPoint {
  double x, y;   // pixels, y downwards
  double depth;  // metres along the view direction; smaller is nearer
};

// Where points fall on the image plane [m]: grows with extend(), then frames a camera.
struct PlaneExtent {
  double right_lo, right_hi, up_lo, up_hi;
  static PlaneExtent none();
  bool empty() const { return right_lo > right_hi; }
};

class ViewCamera {
 public:
  // A camera looking along the view, not yet framed (see frame()).
  // azimuth: direction the camera looks from, degrees counter-clockwise from +x;
  // elevation: degrees above the horizon (oblique only; top looks straight down).
  static ViewCamera looking(View view, double azimuth_deg = -125, double elevation_deg = 35);
  // Adds a point to an extent on this camera's image plane.
  void extend(PlaneExtent& e, double x, double y, double z) const;
  // Scales and places the extent into `width` pixels, less `margin` on every side.
  void frame(const PlaneExtent& e, int width, int margin);

  ScreenPoint project(double x, double y, double z) const;
  // Unit vector from the scene towards the camera: a face is visible when its normal points along it.
  const std::array<double, 3>& towards_camera() const { return back_; }
  double pixels_per_metre() const { return scale_; }
  int width() const { return width_; }
  int height() const { return height_; }  // of the fitted map area
  View view() const { return view_; }

 private:
  View view_ = View::top;
  std::array<double, 3> right_{}, up_{}, back_{};
  double scale_ = 1, right0_ = 0, up0_ = 0;
  int margin_ = 0, width_ = 0, height_ = 0;
};

}  // namespace ort::render

#include "render/map_render.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/clock.h"
#include "render/height_colours.h"
#include "render/map_legend.h"

namespace ort::render {
namespace {

constexpr Rgb kBackground{255, 255, 255};
constexpr Rgb kFreeFootprint{222, 229, 238};
constexpr int kMargin = 16;
// Brightness of a face by its normal axis (x, y, z): a fixed light from above and one side.
constexpr double kFaceShade[3] = {0.82, 0.66, 1.0};

// The face of `box` whose normal is +axis (high side) or -axis, projected, corners in order.
std::array<ScreenPoint, 4> face(const ViewCamera& cam, const VoxelBox& box, int axis, bool high_side) {
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;
  std::array<ScreenPoint, 4> out;
  const double corner[4][2] = {
      {box.lo[i], box.lo[j]}, {box.hi[i], box.lo[j]}, {box.hi[i], box.hi[j]}, {box.lo[i], box.hi[j]}};
  for (int c = 0; c < 4; ++c) {
    double p[3];
    p[axis] = high_side ? box.hi[axis] : box.lo[axis];
    p[i] = corner[c][0];
    p[j] = corner[c][1];
    out[size_t(c)] = cam.project(p[0], p[1], p[2]);
  }
  return out;
}

void draw_occupied(Canvas& canvas, const ViewCamera& cam, const HeightColours& colours,
                   const std::vector<VoxelBox>& boxes) {
  const auto& back = cam.towards_camera();
  for (const VoxelBox& b : boxes) {
    const Rgb base = colours.at((double(b.lo[2]) + b.hi[2]) / 2);
    for (int axis = 0; axis < 3; ++axis) {
      if (std::abs(back[size_t(axis)]) < 1e-9) continue;  // faces seen edge-on
      canvas.fill_face(face(cam, b, axis, back[size_t(axis)] > 0), scaled(base, kFaceShade[axis]));
    }
  }
}

// Free leaves as their footprint on the floor of the picture, under everything else.
void draw_free_footprints(Canvas& canvas, const ViewCamera& cam, const std::vector<VoxelBox>& boxes, float floor_z) {
  for (VoxelBox b : boxes) {
    b.lo[2] = b.hi[2] = floor_z;
    canvas.paint_face(face(cam, b, 2, true), kFreeFootprint);
  }
}

// What the picture shows: the occupied boxes, and the free footprints on their floor.
Box3 drawn_extent(const MapBoxes& boxes) {
  if (boxes.occupied_bounds.empty()) {
    Box3 floor = boxes.free_bounds;
    floor.hi[2] = floor.lo[2];
    return floor;
  }
  Box3 out = boxes.occupied_bounds;
  if (!boxes.free_bounds.empty()) {
    for (int k = 0; k < 2; ++k) {
      out.lo[size_t(k)] = std::min(out.lo[size_t(k)], boxes.free_bounds.lo[size_t(k)]);
      out.hi[size_t(k)] = std::max(out.hi[size_t(k)], boxes.free_bounds.hi[size_t(k)]);
    }
  }
  return out;
}

// The image-plane extent of what is drawn (tighter than the bounding box's in oblique views).
PlaneExtent plane_extent(const ViewCamera& cam, const MapBoxes& boxes, float floor_z) {
  PlaneExtent e = PlaneExtent::none();
  for (const VoxelBox& b : boxes.occupied)
    for (int c = 0; c < 8; ++c)
      cam.extend(e, (c & 1) ? b.hi[0] : b.lo[0], (c & 2) ? b.hi[1] : b.lo[1], (c & 4) ? b.hi[2] : b.lo[2]);
  for (const VoxelBox& b : boxes.free)
    for (int c = 0; c < 4; ++c) cam.extend(e, (c & 1) ? b.hi[0] : b.lo[0], (c & 2) ? b.hi[1] : b.lo[1], floor_z);
  return e;
}

}  // namespace

MapPicture render_map(const octomap::OcTree& tree, const RenderOptions& options) {
  auto t0 = SteadyClock::now();
  const MapBoxes boxes = collect_boxes(tree, options.heights, options.free == FreeSpace::faint);
  RenderStats stats{boxes.occupied.size(), boxes.free.size(), ms_since(t0), 0};

  t0 = SteadyClock::now();
  const Box3 extent = drawn_extent(boxes);
  ViewCamera cam = ViewCamera::looking(options.view, options.azimuth_deg, options.elevation_deg);
  cam.frame(plane_extent(cam, boxes, float(extent.lo[2])), options.width, kMargin);
  const HeightColours colours(options.heights.min.value_or(extent.lo[2]), options.heights.max.value_or(extent.hi[2]));
  Canvas canvas(cam.width(), cam.height() + kLegendHeight, kBackground);
  draw_free_footprints(canvas, cam, boxes.free, float(extent.lo[2]));
  draw_occupied(canvas, cam, colours, boxes.occupied);
  draw_legend(canvas, cam.height(), cam, colours, extent, boxes.resolution);
  stats.raster_ms = ms_since(t0);
  return MapPicture{std::move(canvas), cam, extent, stats};
}

}  // namespace ort::render

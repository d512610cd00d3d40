// The band under a map picture: scale bar, height colour ramp, and the map's extent.
#pragma once

#include <string>

#include "render/canvas.h"
#include "render/height_colours.h"
#include "render/view_camera.h"
#include "render/voxel_boxes.h"

namespace ort::render {

constexpr int kLegendHeight = 64;  // pixels under the map area

// A round length (1, 2 or 5 x 10^k metres) no longer than `max_metres`.
double scale_bar_metres(double max_metres);

// Draws the legend into rows [top, top + kLegendHeight) of the canvas.
void draw_legend(Canvas& canvas, int top, const ViewCamera& camera, const HeightColours& colours, const Box3& extent,
                 double resolution);

}  // namespace ort::render

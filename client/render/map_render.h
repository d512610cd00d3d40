// A picture of an OcTree: occupied voxels as boxes coloured by height, free space as a faint
// footprint on the floor (or hidden), a legend underneath. Software rasterizer, one thread.
#pragma once

#include "render/canvas.h"
#include "render/view_camera.h"
#include "render/voxel_boxes.h"

namespace ort::render {

enum class FreeSpace { faint, hidden };

struct RenderOptions {
  View view = View::top;
  int width = 1200;     // pixels; the height follows from the map's shape
  HeightRange heights;  // voxels outside are cut away; also the colour ramp's range
  FreeSpace free = FreeSpace::faint;
  double azimuth_deg = -125, elevation_deg = 35;  // oblique only
};

struct RenderStats {
  size_t occupied_boxes = 0, free_boxes = 0;
  double collect_ms = 0, raster_ms = 0;
};

struct MapPicture {
  Canvas canvas;
  ViewCamera camera;  // world -> pixel of the map area (the legend is below it)
  Box3 extent;        // of what was drawn
  RenderStats stats;
};

MapPicture render_map(const octomap::OcTree& tree, const RenderOptions& options);

}  // namespace ort::render

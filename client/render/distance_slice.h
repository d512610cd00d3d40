// A horizontal slice of a distance field as a picture: obstacles black, distances from red
// (near) through yellow and green to blue (at the clamp), a colour bar in metres and a scale
// bar, north (+y) up, written as PNG (`octomap-rt query distance box --png`).
#pragma once

#include <string>
#include <vector>

namespace ort::render {

struct DistanceSlice {
  int width = 0, height = 0;                 // cells; row j holds cells i = 0 .. width - 1
  std::vector<float> distance;               // width * height [m], 0 = obstacle
  double max_distance = 1;                   // [m] the clamp
  double cell_size = 0.1;                    // [m]
  double origin_x = 0, origin_y = 0, z = 0;  // [m] min corner of cell (0, 0); the slice's height
};

// Cells are drawn `cell_px` pixels a side (0: about 800 px wide). Throws PngError.
void write_distance_slice_png(const DistanceSlice& slice, const std::string& path, int cell_px = 0);

}  // namespace ort::render

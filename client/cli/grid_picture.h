// A 2D grid as a picture a person can read: free, occupied and unknown cells in three
// colours, a legend and a scale bar in metres, written as PNG (libpng, client/render/).
#pragma once

#include <string>

#include "query_client/query_client.h"

namespace ort::client {

// Cells are drawn `cell_px` pixels a side (0: chosen so the picture is about 800 px wide),
// north (+y) up. Throws render::PngError when the file cannot be written.
void write_grid_png(const Grid& grid, const std::string& path, int cell_px = 0);

}  // namespace ort::client

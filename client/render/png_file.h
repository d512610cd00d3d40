// PNG files of a Canvas, through libpng.
#pragma once

#include <stdexcept>
#include <string>

#include "render/canvas.h"

namespace ort::render {

class PngError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

void write_png(const Canvas& canvas, const std::string& path);  // 8-bit RGB
Canvas read_png(const std::string& path);                       // any PNG, as 8-bit RGB

}  // namespace ort::render

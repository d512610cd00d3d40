#include "render/png_file.h"

#include <csetjmp>
#include <cstdio>
#include <memory>
#include <vector>

#include <png.h>

namespace ort::render {
namespace {

struct FileCloser {
  void operator()(FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<FILE, FileCloser>;

File open(const std::string& path, const char* mode) {
  File f(std::fopen(path.c_str(), mode));
  if (!f) throw PngError("cannot open " + path + (mode[0] == 'w' ? " for writing" : ""));
  return f;
}

}  // namespace

void write_png(const Canvas& canvas, const std::string& path) {
  File file = open(path, "wb");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    throw PngError("libpng: out of memory");
  }
  std::vector<png_bytep> rows(size_t(canvas.height()));
  if (setjmp(png_jmpbuf(png))) {  // libpng reports errors by longjmp: nothing with a destructor lives below
    png_destroy_write_struct(&png, &info);
    throw PngError("libpng could not write " + path);
  }
  png_init_io(png, file.get());
  png_set_IHDR(png, info, png_uint_32(canvas.width()), png_uint_32(canvas.height()), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  static_assert(sizeof(Rgb) == 3, "Canvas pixels are written as packed RGB rows");
  auto* base = reinterpret_cast<png_bytep>(const_cast<Rgb*>(canvas.pixels().data()));
  for (size_t y = 0; y < rows.size(); ++y) rows[y] = base + y * size_t(canvas.width()) * 3;
  png_write_info(png, info);
  png_write_image(png, rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fflush(file.get()) != 0) throw PngError("could not write " + path);
}

Canvas read_png(const std::string& path) {
  File file = open(path, "rb");
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    throw PngError("libpng: out of memory");
  }
  std::vector<uint8_t> data;
  std::vector<png_bytep> rows;
  png_uint_32 width = 0, height = 0;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw PngError(path + " is not a readable PNG");
  }
  png_init_io(png, file.get());
  png_read_info(png, info);
  width = png_get_image_width(png, info);
  height = png_get_image_height(png, info);
  png_set_expand(png);  // palette and grey to RGB, 16 bit to 8, alpha dropped below
  png_set_strip_16(png);
  png_set_strip_alpha(png);
  png_set_gray_to_rgb(png);
  png_read_update_info(png, info);
  data.resize(size_t(width) * height * 3);
  rows.resize(height);
  for (size_t y = 0; y < height; ++y) rows[y] = data.data() + y * size_t(width) * 3;
  png_read_image(png, rows.data());
  png_destroy_read_struct(&png, &info, nullptr);
  Canvas canvas(int(width), int(height), Rgb{});
  for (png_uint_32 y = 0; y < height; ++y)
    for (png_uint_32 x = 0; x < width; ++x) {
      const uint8_t* p = rows[y] + size_t(x) * 3;
      canvas.set(int(x), int(y), Rgb{p[0], p[1], p[2]});
    }
  return canvas;
}

}  // namespace ort::render

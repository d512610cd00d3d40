// A 5x7 pixel font for the labels of map pictures (digits, lower-case letters and the
// punctuation of numbers and units), so the renderer needs no font files.
#pragma once

#include <string_view>

#include "render/canvas.h"

namespace ort::render {

constexpr int kGlyphWidth = 5, kGlyphHeight = 7, kGlyphAdvance = 6;

// Draws `text` with its top-left corner at (x, y), each font pixel `scale` x `scale`.
// Characters without a glyph are drawn as blanks. Returns the x after the last character.
int draw_text(Canvas& canvas, int x, int y, std::string_view text, Rgb colour, int scale = 2);
int text_width(std::string_view text, int scale = 2);

}  // namespace ort::render

#pragma once
// A tiny built-in 5x7 bitmap font for figure labels (digits, A-Z, a little punctuation; lower case is
// drawn as upper case, anything else as '?').
#include <string>

#include "render/image/png_io.h"

namespace kf::render {

constexpr int kGlyphWidth = 5, kGlyphHeight = 7, kGlyphAdvance = 6;  // font pixels

// Width and height in image pixels of `text` drawn at `scale` image pixels per font pixel.
int text_width(const std::string& text, int scale);
inline int text_height(int scale) { return kGlyphHeight * scale; }
// Draws `text` with its top-left corner at (x, y); pixels outside the image are skipped.
void draw_text(Image& image, int x, int y, const std::string& text, int scale, const uint8_t rgb[3]);

}  // namespace kf::render

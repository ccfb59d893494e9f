#pragma once
// Pictures of where two frames differ, written beside a failing comparison.
#include "render/image/png_io.h"

namespace kf::render {

// Heat map of the per-pixel largest channel difference |a - b|: black where equal (or within
// `tolerance` 8-bit levels, shown dark grey), then red → yellow → white as the difference grows to 255.
// a and b: one size (else std::invalid_argument), RGB or RGBA. Returns RGB of that size.
Image diff_heatmap(const Image& a, const Image& b, int tolerance);

// Reference, actual and heat map side by side with a 4-pixel grey gap. All one size. Returns RGB.
Image side_by_side(const Image& reference, const Image& actual, const Image& heatmap);

}  // namespace kf::render

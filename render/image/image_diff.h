#pragma once
// Comparing two images of one size, for regression tests and tooling.
#include "render/image/png_io.h"

namespace kf::render {

struct ImageDifference {
  double mean_error = 0.0;          // mean |a - b| over all channels, in 8-bit levels
  double differing_fraction = 0.0;  // pixels where some channel differs by more than the threshold
  int max_error = 0;                // 8-bit levels
};

// a and b must have the same size (else std::invalid_argument); channels beyond RGB are ignored.
ImageDifference compare_images(const Image& a, const Image& b, int threshold = 8);
// |a - b| per channel scaled x4 and clamped, RGB: where to look when a comparison fails.
Image difference_image(const Image& a, const Image& b);

}  // namespace kf::render

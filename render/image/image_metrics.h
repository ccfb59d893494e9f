#pragma once
// Per-frame error measures between a rendered image and its reference (keyframe compare).
#include "render/image/png_io.h"

namespace kf::render {

struct ImageMetrics {
  int max_abs = 0;             // largest |a - b| over pixels and RGB channels, 8-bit levels
  double mean_abs = 0.0;       // mean |a - b| over pixels and RGB channels, 8-bit levels
  double rmse = 0.0;           // root mean square of a - b over pixels and RGB channels, 8-bit levels
  double psnr = 0.0;           // 20 log10(255 / rmse) in dB; +infinity for identical images
  double over_fraction = 0.0;  // pixels where some channel differs by more than `tolerance`, 0..1
};

// a and b: the same width and height (else std::invalid_argument), RGB or RGBA (alpha is ignored).
// tolerance: per-pixel, per-channel allowance in 8-bit levels (0: any difference counts).
ImageMetrics image_metrics(const Image& a, const Image& b, int tolerance);

}  // namespace kf::render

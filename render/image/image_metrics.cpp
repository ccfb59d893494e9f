#include "render/image/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>

namespace kf::render {

ImageMetrics image_metrics(const Image& a, const Image& b, int tolerance) {
  if (a.width != b.width || a.height != b.height) throw std::invalid_argument("images differ in size");
  ImageMetrics m;
  // Integer sums are exact (255^2 x 3 x 4096^2 fits easily), so metrics do not depend on summation order.
  long long sum = 0, sum_sq = 0, over = 0;
  // Alpha counts in each pixel's largest difference when either image has one (a missing alpha is opaque),
  // so a transparent frame does not pass against an opaque one; the means stay over colour.
  const bool alpha = a.channels == 4 || b.channels == 4;
  for (int y = 0; y < a.height; ++y) {
    const uint8_t* pa = a.at(0, y);
    const uint8_t* pb = b.at(0, y);
    for (int x = 0; x < a.width; ++x, pa += a.channels, pb += b.channels) {
      int worst = 0;
      if (alpha) worst = std::abs((a.channels == 4 ? pa[3] : 255) - (b.channels == 4 ? pb[3] : 255));
      for (int c = 0; c < 3; ++c) {
        const int e = std::abs(int(pa[c]) - int(pb[c]));
        sum += e;
        sum_sq += e * e;
        worst = std::max(worst, e);
      }
      m.max_abs = std::max(m.max_abs, worst);
      over += worst > tolerance;
    }
  }
  const double samples = 3.0 * std::max(1.0, double(a.width) * a.height);
  m.mean_abs = double(sum) / samples;
  m.rmse = std::sqrt(double(sum_sq) / samples);
  m.psnr = sum_sq == 0 ? std::numeric_limits<double>::infinity() : 20.0 * std::log10(255.0 / m.rmse);
  m.over_fraction = double(over) / (samples / 3.0);
  return m;
}

}  // namespace kf::render

#include "render/image/image_diff.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

namespace kf::render {

ImageDifference compare_images(const Image& a, const Image& b, int threshold) {
  if (a.width != b.width || a.height != b.height) throw std::invalid_argument("images differ in size");
  ImageDifference d;
  long sum = 0, differing = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      int worst = 0;
      for (int c = 0; c < 3; ++c) {
        const int e = std::abs(int(a.at(x, y)[std::min(c, a.channels - 1)]) - int(b.at(x, y)[std::min(c, b.channels - 1)]));
        sum += e;
        worst = std::max(worst, e);
      }
      d.max_error = std::max(d.max_error, worst);
      if (worst > threshold) ++differing;
    }
  const double pixels = double(std::max(1, a.width * a.height));
  d.mean_error = double(sum) / (3.0 * pixels);
  d.differing_fraction = double(differing) / pixels;
  return d;
}

Image difference_image(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height) throw std::invalid_argument("images differ in size");
  Image out(a.width, a.height, 3);
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const int e = std::abs(int(a.at(x, y)[std::min(c, a.channels - 1)]) - int(b.at(x, y)[std::min(c, b.channels - 1)]));
        out.at(x, y)[c] = uint8_t(std::min(255, 4 * e));
      }
  return out;
}

}  // namespace kf::render

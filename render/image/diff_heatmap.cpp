#include "render/image/diff_heatmap.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace kf::render {

namespace {
constexpr int kGap = 4;
constexpr uint8_t kGapGrey = 128;

// Black → red → yellow → white; small differences are stretched (square root) so a one-level change
// is still visible next to a missing object.
void heat_colour(int e, uint8_t rgb[3]) {
  const double t = std::sqrt(double(e) / 255.0) * 3.0;
  rgb[0] = uint8_t(std::lround(255.0 * std::clamp(t, 0.0, 1.0)));
  rgb[1] = uint8_t(std::lround(255.0 * std::clamp(t - 1.0, 0.0, 1.0)));
  rgb[2] = uint8_t(std::lround(255.0 * std::clamp(t - 2.0, 0.0, 1.0)));
}
}  // namespace

Image diff_heatmap(const Image& a, const Image& b, int tolerance) {
  if (a.width != b.width || a.height != b.height) throw std::invalid_argument("images differ in size");
  Image out(a.width, a.height, 3);
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      int worst = 0;
      for (int c = 0; c < 4; ++c) {  // alpha too (a missing one is opaque), as image_metrics counts it
        const int va = c < a.channels ? a.at(x, y)[c] : 255, vb = c < b.channels ? b.at(x, y)[c] : 255;
        worst = std::max(worst, std::abs(va - vb));
      }
      uint8_t* o = out.at(x, y);
      if (worst == 0) continue;
      if (worst <= tolerance) {
        o[0] = o[1] = o[2] = 40;  // differs, but within the tolerance
        continue;
      }
      heat_colour(worst, o);
    }
  return out;
}

Image side_by_side(const Image& reference, const Image& actual, const Image& heatmap) {
  const int w = reference.width, h = reference.height;
  if (actual.width != w || actual.height != h || heatmap.width != w || heatmap.height != h)
    throw std::invalid_argument("images differ in size");
  Image out(3 * w + 2 * kGap, h, 3);
  std::fill(out.pixels.begin(), out.pixels.end(), kGapGrey);
  const Image* parts[3] = {&reference, &actual, &heatmap};
  for (int k = 0; k < 3; ++k)
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        std::copy_n(parts[k]->at(x, y), 3, out.at(k * (w + kGap) + x, y));
  return out;
}

}  // namespace kf::render

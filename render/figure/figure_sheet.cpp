#include "render/figure/figure_sheet.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "render/figure/bitmap_font.h"

namespace kf::render {

namespace {
constexpr int kMargin = 16, kGap = 10, kScale = 2;
constexpr uint8_t kInk[3] = {20, 20, 20};

void blit(Image& dst, const Image& src, int x0, int y0) {
  for (int y = 0; y < src.height; ++y)
    for (int x = 0; x < src.width; ++x)
      for (int c = 0; c < 3; ++c) dst.at(x0 + x, y0 + y)[c] = src.at(x, y)[std::min(c, src.channels - 1)];
}
}  // namespace

Image compose_sheet(const std::string& title, const std::vector<FigureRow>& rows) {
  int tw = 0, th = 0, cols = 0;
  for (const auto& r : rows)
    for (const auto& t : r.tiles) {
      if (tw == 0) tw = t.width, th = t.height;
      if (t.width != tw || t.height != th) throw std::invalid_argument("figure tiles differ in size");
    }
  for (const auto& r : rows) cols = std::max(cols, int(r.tiles.size()));
  const int line = text_height(kScale) + 8;
  const int W = std::max(2 * kMargin + cols * tw + std::max(cols - 1, 0) * kGap, 2 * kMargin + text_width(title, kScale));
  const int row_h = line + th + line;
  const int H = kMargin + line + int(rows.size()) * (row_h + kGap) + kMargin;
  Image sheet(W, H, 3);
  std::fill(sheet.pixels.begin(), sheet.pixels.end(), uint8_t(255));
  draw_text(sheet, kMargin, kMargin, title, kScale, kInk);
  int y = kMargin + line + kGap;
  for (const auto& r : rows) {
    draw_text(sheet, kMargin, y, r.label, kScale, kInk);
    for (size_t k = 0; k < r.tiles.size(); ++k) {
      const int x = kMargin + int(k) * (tw + kGap);
      blit(sheet, r.tiles[k], x, y + line);
      if (k < r.captions.size()) {
        const int cx = x + (tw - text_width(r.captions[k], kScale)) / 2;
        draw_text(sheet, std::max(cx, x), y + line + th + 6, r.captions[k], kScale, kInk);
      }
    }
    y += row_h + kGap;
  }
  return sheet;
}

Image overlay_frames(const std::vector<Image>& frames) {
  if (frames.empty()) return Image();
  Image out = frames.back();
  const size_t K = frames.size();
  for (size_t k = 0; k + 1 < K; ++k) {
    const double a = 0.25 + 0.6 * double(k) / double(std::max<size_t>(K - 1, 1));
    const Image& f = frames[k];
    for (size_t i = 0; i < out.pixels.size(); ++i) {
      const double d = double(f.pixels[i]) - double(out.pixels[i]);
      if (d < 0) out.pixels[i] = uint8_t(std::lround(double(out.pixels[i]) + a * d));
    }
  }
  return out;
}

}  // namespace kf::render

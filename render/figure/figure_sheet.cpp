#include "render/figure/figure_sheet.h"

#include <cairo-ft.h>
#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "core/error.h"

namespace kf::render {

namespace {

constexpr const char* kFont = "DejaVu Sans";  // Debian's fonts-dejavu-core
constexpr double kTitleSize = 20, kLabelSize = 15, kTileCaptionSize = 14, kCaptionSize = 15;  // pixels
constexpr double kMargin = 16, kGap = 10, kLead = 1.35;  // pixels; line height = lead x font size
constexpr double kInk = 0.08;                            // grey level of the type
constexpr double kPdfScale = 0.75;                       // points per pixel

using Surface = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;
using Context = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;

void set_font(cairo_t* cr, double size, bool bold = false) {
  cairo_select_font_face(cr, kFont, CAIRO_FONT_SLANT_NORMAL, bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
}

double text_width(cairo_t* cr, const std::string& s) {
  cairo_text_extents_t e;
  cairo_text_extents(cr, s.c_str(), &e);
  return e.x_advance;
}

// Fontconfig silently substitutes a missing family; a sheet set in another face would look wrong, so
// say what to install instead.
void require_font(cairo_t* cr) {
  set_font(cr, kLabelSize);
  cairo_scaled_font_t* sf = cairo_get_scaled_font(cr);
  std::string family;
  if (cairo_scaled_font_get_type(sf) == CAIRO_FONT_TYPE_FT)
    if (FT_Face face = cairo_ft_scaled_font_lock_face(sf)) {
      family = face->family_name ? face->family_name : "";
      cairo_ft_scaled_font_unlock_face(sf);
    }
  if (family != kFont)
    throw OutputError(std::string("figure: the font \"") + kFont + "\" is not installed (found \"" + family +
                      "\"); install it with apt-get install fonts-dejavu-core");
}

// Greedy word wrap of `text` into lines no wider than `width` at the current font.
std::vector<std::string> wrap(cairo_t* cr, const std::string& text, double width) {
  std::vector<std::string> lines;
  std::istringstream words(text);
  std::string word, line;
  while (words >> word) {
    const std::string longer = line.empty() ? word : line + " " + word;
    if (!line.empty() && text_width(cr, longer) > width) {
      lines.push_back(line);
      line = word;
    } else {
      line = longer;
    }
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

// Positions of everything on the sheet, in pixels; measured once and drawn on any surface.
struct Layout {
  double width = 0, height = 0;
  int tile_w = 0, tile_h = 0;
  double title_y = 0;                  // baseline
  std::vector<double> label_y, tile_y;  // per row: label baseline, tile top
  std::vector<std::string> caption_lines;
  double caption_y = 0;                 // first caption baseline
};

Layout layout_sheet(cairo_t* cr, const FigureSheet& s) {
  Layout L;
  int cols = 0;
  for (const auto& r : s.rows) {
    for (const auto& t : r.tiles) {
      if (L.tile_w == 0) L.tile_w = t.width, L.tile_h = t.height;
      if (t.width != L.tile_w || t.height != L.tile_h) throw std::invalid_argument("figure tiles differ in size");
    }
    cols = std::max(cols, int(r.tiles.size()));
  }
  set_font(cr, kTitleSize, true);
  L.width = std::max(2 * kMargin + cols * L.tile_w + std::max(cols - 1, 0) * kGap,
                     2 * kMargin + std::ceil(text_width(cr, s.title)));
  double y = kMargin;
  if (!s.title.empty()) {
    L.title_y = y + kTitleSize;
    y += kLead * kTitleSize + kGap;
  }
  for (const auto& r : s.rows) {
    if (!r.label.empty()) {
      L.label_y.push_back(y + kLabelSize);
      y += kLead * kLabelSize;
    } else {
      L.label_y.push_back(0);
    }
    L.tile_y.push_back(y);
    y += L.tile_h;
    if (!r.captions.empty()) y += kLead * kTileCaptionSize + 4;
    y += kGap;
  }
  set_font(cr, kCaptionSize);
  L.caption_lines = wrap(cr, s.caption, L.width - 2 * kMargin);
  if (!L.caption_lines.empty()) {
    y += 4;
    L.caption_y = y + kCaptionSize;
    y += kLead * kCaptionSize * double(L.caption_lines.size());
  }
  L.height = std::ceil(y + kMargin - kGap);
  return L;
}

Surface tile_surface(const Image& img) {
  Surface s(cairo_image_surface_create(CAIRO_FORMAT_RGB24, img.width, img.height), cairo_surface_destroy);
  cairo_surface_flush(s.get());
  unsigned char* data = cairo_image_surface_get_data(s.get());
  const int stride = cairo_image_surface_get_stride(s.get());
  for (int y = 0; y < img.height; ++y) {
    auto* row = reinterpret_cast<uint32_t*>(data + size_t(y) * stride);
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = img.at(x, y);
      row[x] = 0xff000000u | uint32_t(p[0]) << 16 | uint32_t(p[1]) << 8 | uint32_t(p[2]);
    }
  }
  cairo_surface_mark_dirty(s.get());
  return s;
}

void show_text(cairo_t* cr, double x, double baseline, const std::string& s) {
  cairo_move_to(cr, x, baseline);
  cairo_show_text(cr, s.c_str());
}

void draw_sheet(cairo_t* cr, const FigureSheet& s, const Layout& L) {
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_set_source_rgb(cr, kInk, kInk, kInk);
  if (!s.title.empty()) {
    set_font(cr, kTitleSize, true);
    show_text(cr, kMargin, L.title_y, s.title);
  }
  for (size_t i = 0; i < s.rows.size(); ++i) {
    const FigureRow& r = s.rows[i];
    if (!r.label.empty()) {
      set_font(cr, kLabelSize, true);
      show_text(cr, kMargin, L.label_y[i], r.label);
    }
    set_font(cr, kTileCaptionSize);
    for (size_t k = 0; k < r.tiles.size(); ++k) {
      const double x = kMargin + double(k) * (L.tile_w + kGap);
      const Surface tile = tile_surface(r.tiles[k]);
      cairo_save(cr);
      cairo_set_source_surface(cr, tile.get(), x, L.tile_y[i]);
      cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);  // tiles land on whole pixels
      cairo_rectangle(cr, x, L.tile_y[i], L.tile_w, L.tile_h);
      cairo_fill(cr);
      cairo_restore(cr);
      if (k < r.captions.size()) {
        const double w = text_width(cr, r.captions[k]);
        show_text(cr, x + std::max(0.0, (L.tile_w - w) / 2), L.tile_y[i] + L.tile_h + 4 + kTileCaptionSize,
                  r.captions[k]);
      }
    }
  }
  set_font(cr, kCaptionSize);
  for (size_t k = 0; k < L.caption_lines.size(); ++k)
    show_text(cr, kMargin, L.caption_y + double(k) * kLead * kCaptionSize, L.caption_lines[k]);
}

// A scratch context to measure text with, before the sheet's size is known.
Layout measure(const FigureSheet& s) {
  Surface scratch(cairo_image_surface_create(CAIRO_FORMAT_RGB24, 1, 1), cairo_surface_destroy);
  Context cr(cairo_create(scratch.get()), cairo_destroy);
  require_font(cr.get());
  return layout_sheet(cr.get(), s);
}

cairo_status_t append_bytes(void* closure, const unsigned char* data, unsigned int n) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), n);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

Image compose_sheet(const FigureSheet& s) {
  const Layout L = measure(s);
  const int W = int(L.width), H = int(L.height);
  Surface surface(cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H), cairo_surface_destroy);
  {
    Context cr(cairo_create(surface.get()), cairo_destroy);
    draw_sheet(cr.get(), s, L);
    if (cairo_status(cr.get()) != CAIRO_STATUS_SUCCESS)
      throw OutputError(std::string("figure: cannot draw the sheet: ") + cairo_status_to_string(cairo_status(cr.get())));
  }
  cairo_surface_flush(surface.get());
  const unsigned char* data = cairo_image_surface_get_data(surface.get());
  const int stride = cairo_image_surface_get_stride(surface.get());
  Image out(W, H, 3);
  for (int y = 0; y < H; ++y) {
    const auto* row = reinterpret_cast<const uint32_t*>(data + size_t(y) * stride);
    for (int x = 0; x < W; ++x) {
      uint8_t* p = out.at(x, y);
      p[0] = uint8_t(row[x] >> 16), p[1] = uint8_t(row[x] >> 8), p[2] = uint8_t(row[x]);
    }
  }
  return out;
}

std::string sheet_pdf(const FigureSheet& s) {
  const Layout L = measure(s);
  std::string bytes;
  {
    Surface surface(cairo_pdf_surface_create_for_stream(append_bytes, &bytes, L.width * kPdfScale, L.height * kPdfScale),
                    cairo_surface_destroy);
    Context cr(cairo_create(surface.get()), cairo_destroy);
    cairo_scale(cr.get(), kPdfScale, kPdfScale);
    draw_sheet(cr.get(), s, L);
    cairo_show_page(cr.get());
    if (cairo_status(cr.get()) != CAIRO_STATUS_SUCCESS)
      throw OutputError(std::string("figure: cannot write the PDF: ") + cairo_status_to_string(cairo_status(cr.get())));
    cairo_surface_finish(surface.get());
    if (cairo_surface_status(surface.get()) != CAIRO_STATUS_SUCCESS)
      throw OutputError(std::string("figure: cannot write the PDF: ") +
                        cairo_status_to_string(cairo_surface_status(surface.get())));
  }
  return bytes;
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

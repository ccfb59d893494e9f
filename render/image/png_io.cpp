#include "render/image/png_io.h"

#include <png.h>

#include <cstdio>
#include <memory>
#include <sstream>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"

namespace kf::render {

namespace {
void append_bytes(png_structp png, png_bytep data, png_size_t n) {
  auto* out = static_cast<std::string*>(png_get_io_ptr(png));
  out->append(reinterpret_cast<const char*>(data), n);
}
void no_flush(png_structp) {}

// libpng prints errors and warnings to stderr by default; keyframe reports one line of its own instead,
// quoting libpng's reason (kept in the error pointer's buffer).
[[noreturn]] void quiet_error(png_structp png, png_const_charp message) {
  auto* reason = static_cast<std::string*>(png_get_error_ptr(png));
  if (reason) *reason = message ? message : "";
  png_longjmp(png, 1);
}
void quiet_warning(png_structp, png_const_charp) {}
}  // namespace

void write_png(const std::filesystem::path& path, const Image& image) {
  std::string bytes;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) throw OutputError(path.string() + ": cannot start PNG encoder");
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw OutputError(path.string() + ": PNG encoding failed");
  }
  png_set_write_fn(png, &bytes, append_bytes, no_flush);
  png_set_IHDR(png, info, image.width, image.height, 8, image.channels == 4 ? PNG_COLOR_TYPE_RGBA : PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 3);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y) png_write_row(png, const_cast<png_bytep>(image.at(0, y)));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  write_file_atomic(path, bytes);
}

namespace {
// Opens `path`, checks the signature and reads the header; `body(png, info)` then decodes. Frees libpng's
// state on every path; libpng's errors become InputError naming the file.
template <typename Body>
auto with_png_reader(const std::filesystem::path& path, Body body) {
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "rb"), std::fclose);
  if (!f) throw InputError(path.string() + ": cannot open PNG");
  unsigned char sig[8];
  if (std::fread(sig, 1, 8, f.get()) != 8 || png_sig_cmp(sig, 0, 8)) throw InputError(path.string() + ": not a PNG file");
  std::string reason;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &reason, quiet_error, quiet_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) throw InputError(path.string() + ": cannot start PNG decoder");
  decltype(body(png, info)) result{};
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw InputError(path.string() + ": corrupt or truncated PNG (" + (reason.empty() ? "libpng error" : reason) + ")");
  }
  png_init_io(png, f.get());
  png_set_sig_bytes(png, 8);
  png_read_info(png, info);
  // The header's size is checked before anything is allocated for the rows.
  const uint32_t w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  if (w > kMaxPngSide || h > kMaxPngSide || uint64_t(w) * h > kMaxPngPixels) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw InputError(path.string() + ": " + std::to_string(w) + "x" + std::to_string(h) +
                     " pixels, larger than keyframe reads (at most " + std::to_string(kMaxPngSide) +
                     " a side and " + std::to_string(kMaxPngPixels) + " pixels)");
  }
  result = body(png, info);
  png_destroy_read_struct(&png, &info, nullptr);
  return result;
}
}  // namespace

PngHeader read_png_header(const std::filesystem::path& path) {
  return with_png_reader(path, [](png_structp png, png_infop info) {
    return PngHeader{int(png_get_image_width(png, info)), int(png_get_image_height(png, info))};
  });
}

Image read_png(const std::filesystem::path& path) {
  // The image lives outside the reader so that libpng's longjmp on a corrupt row skips no destructor.
  Image img;
  std::vector<png_bytep> rows;
  with_png_reader(path, [&](png_structp png, png_infop info) {
    png_set_strip_16(png);
    png_set_palette_to_rgb(png);
    png_set_expand_gray_1_2_4_to_8(png);
    png_set_tRNS_to_alpha(png);  // a transparent colour or palette entry becomes an alpha channel
    png_set_gray_to_rgb(png);
    png_set_interlace_handling(png);  // Adam7: libpng assembles the seven passes
    png_read_update_info(png, info);
    const int channels = png_get_channels(png, info);
    img = Image(int(png_get_image_width(png, info)), int(png_get_image_height(png, info)), channels);
    rows.resize(size_t(img.height));
    for (int y = 0; y < img.height; ++y) rows[size_t(y)] = img.at(0, y);
    png_read_image(png, rows.data());
    png_read_end(png, nullptr);
    return 0;
  });
  return img;
}

}  // namespace kf::render

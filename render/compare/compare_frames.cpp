#include "render/compare/compare_frames.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <set>
#include <stdexcept>

#include "core/atomic_file.h"
#include "core/error.h"
#include "render/compare/compare_report.h"
#include "render/image/diff_heatmap.h"

namespace kf::render {

namespace fs = std::filesystem;

namespace {

// A run directory's frames/, or the directory itself.
fs::path frames_dir(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir / "frames", ec) ? dir / "frames" : dir;
}

// File names of the PNGs directly in `dir` (hidden ones, such as half-written temporaries, skipped).
std::set<std::string> png_names(const fs::path& dir) {
  std::set<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (it->path().extension() == ".png" && name[0] != '.' && it->is_regular_file(ec)) names.insert(name);
  }
  if (ec) throw InputError(dir.string() + ": cannot list (" + ec.message() + ")");
  return names;
}

std::string percent(double fraction) {
  char s[32];
  std::snprintf(s, sizeof s, "%.3g%%", 100.0 * fraction);
  return s;
}

std::string number(double v) {
  char s[32];
  std::snprintf(s, sizeof s, "%.3g", v);
  return s;
}

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in && !in.eof()) throw InputError(path.string() + ": cannot read");
  return bytes;
}

// Removes what an earlier comparison left in `out` so that only this one's failures show.
void remove_old_diffs(const fs::path& out) {
  std::vector<fs::path> old;
  std::error_code ec;
  for (fs::directory_iterator it(out, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.ends_with("_diff.png") || name.ends_with("_side.png")) old.push_back(it->path());
  }
  for (const auto& p : old) fs::remove(p, ec);
}

}  // namespace

CompareThresholds noise_thresholds() {
  CompareThresholds t;
  t.tolerance = 48;
  t.max_fraction = 0.01;
  t.max_mean = 3.0;
  return t;
}

std::string threshold_failure(const ImageMetrics& m, const CompareThresholds& t) {
  if (m.over_fraction > t.max_fraction)
    return percent(m.over_fraction) + " of pixels differ by more than " + std::to_string(t.tolerance) +
           " levels (allowed " + percent(t.max_fraction) + ", largest difference " + std::to_string(m.max_abs) + ")";
  if (m.mean_abs > t.max_mean)
    return "mean difference " + number(m.mean_abs) + " levels (allowed " + number(t.max_mean) + ")";
  if (t.min_psnr > 0.0 && m.psnr < t.min_psnr)
    return "PSNR " + number(m.psnr) + " dB (at least " + number(t.min_psnr) + " dB required)";
  return {};
}

CompareResult compare_frames(const CompareRequest& r) {
  const CompareThresholds& t = r.thresholds;
  if (t.tolerance < 0 || t.tolerance > 255) throw InputError("compare: tolerance must be 0..255 levels");
  if (!(t.max_fraction >= 0.0 && t.max_fraction <= 1.0)) throw InputError("compare: max fraction must be 0..1");
  if (!(t.max_mean >= 0.0) || !(t.min_psnr >= 0.0)) throw InputError("compare: thresholds must not be negative");
  std::error_code ec;
  if (!fs::is_directory(r.actual, ec)) throw InputError(r.actual.string() + ": not a directory");
  const fs::path actual = frames_dir(r.actual);
  const std::set<std::string> names = png_names(actual);
  if (names.empty()) throw InputError(actual.string() + ": no PNG frames to compare (empty directory)");
  const bool have_reference = fs::is_directory(r.reference, ec);
  if (!have_reference && !r.update)
    throw InputError(r.reference.string() + ": no such reference directory (--update creates it from the frames)");
  const fs::path reference = have_reference ? frames_dir(r.reference) : r.reference;
  const std::set<std::string> ref_names = have_reference ? png_names(reference) : std::set<std::string>{};
  if (ref_names.empty() && !r.update)
    throw InputError(reference.string() + ": no PNG reference frames (empty directory; --update fills it)");
  for (const auto& n : ref_names)
    if (!names.count(n))
      throw InputError((actual / n).string() + ": missing (the reference " + (reference / n).string() + " has it)");
  if (!r.update)
    for (const auto& n : names)
      if (!ref_names.count(n))
        throw InputError((reference / n).string() + ": missing reference for " + (actual / n).string() +
                         " (--update accepts new frames)");

  // First pass: metrics only, so that bad input stops us before anything is written.
  CompareResult res;
  for (const auto& n : names) {
    FrameResult f;
    f.name = n;
    // Sizes from the headers first: a mismatch is reported before a large image is decoded.
    const PngHeader ha = read_png_header(actual / n);
    if (ref_names.count(n)) {
      const PngHeader hb = read_png_header(reference / n);
      if (ha.width != hb.width || ha.height != hb.height)
        throw InputError((actual / n).string() + ": " + std::to_string(ha.width) + "x" + std::to_string(ha.height) +
                         " pixels, but the reference " + (reference / n).string() + " has " +
                         std::to_string(hb.width) + "x" + std::to_string(hb.height));
    }
    const Image a = read_png(actual / n);
    f.width = a.width;
    f.height = a.height;
    if (ref_names.count(n)) {
      const Image b = read_png(reference / n);
      f.metrics = image_metrics(a, b, t.tolerance);
      f.why = threshold_failure(f.metrics, t);
    } else {
      f.is_new = true;
      ++res.added;
    }
    f.pass = f.why.empty();
    res.failed += !f.pass;
    res.frames.push_back(std::move(f));
  }

  res.out_dir = !r.out_dir.empty() ? r.out_dir : fs::weakly_canonical(actual, ec).parent_path() / "compare";
  // Diff images among the frames would be paired as frames next time.
  for (const fs::path& d : {actual, reference})
    if (fs::weakly_canonical(res.out_dir, ec) == fs::weakly_canonical(d, ec))
      throw InputError(res.out_dir.string() + ": reports cannot go into a frames directory (choose another --out)");
  ensure_directory(res.out_dir);
  remove_old_diffs(res.out_dir);
  for (auto& f : res.frames) {
    if (f.pass) continue;
    const Image a = read_png(actual / f.name), b = read_png(reference / f.name);
    const std::string stem = fs::path(f.name).stem().string();
    f.diff = stem + "_diff.png";
    f.side = stem + "_side.png";
    const Image heat = diff_heatmap(a, b, t.tolerance);
    write_png(res.out_dir / f.diff, heat);
    write_png(res.out_dir / f.side, side_by_side(b, a, heat));
  }
  if (r.update) {
    ensure_directory(reference);
    for (const auto& f : res.frames) {
      if (!f.is_new && f.metrics.max_abs == 0) continue;  // the same pixels already
      write_file_atomic(reference / f.name, read_bytes(actual / f.name));
      ++res.updated;
    }
  }
  res.json = res.out_dir / "compare.json";
  res.junit = res.out_dir / "junit.xml";
  write_file_atomic(res.json, compare_json(r, res));
  write_file_atomic(res.junit, compare_junit(r, res));
  return res;
}

}  // namespace kf::render

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

namespace {

void check_thresholds(const CompareThresholds& t) {
  if (t.tolerance < 0 || t.tolerance > 255) throw InputError("compare: tolerance must be 0..255 levels");
  if (!(t.max_fraction >= 0.0 && t.max_fraction <= 1.0)) throw InputError("compare: max fraction must be 0..1");
  if (!(t.max_mean >= 0.0) || !(t.min_psnr >= 0.0)) throw InputError("compare: thresholds must not be negative");
}

// The two frame directories and the PNG names each holds.
struct FramePairs {
  fs::path actual, reference;
  std::set<std::string> names, ref_names;
};

FramePairs find_frame_pairs(const CompareRequest& r) {
  FramePairs p;
  std::error_code ec;
  if (!fs::is_directory(r.actual, ec)) throw InputError(r.actual.string() + ": not a directory");
  p.actual = frames_dir(r.actual);
  p.names = png_names(p.actual);
  if (p.names.empty()) throw InputError(p.actual.string() + ": no PNG frames to compare (empty directory)");
  const bool have_reference = fs::is_directory(r.reference, ec);
  if (!have_reference && !r.update)
    throw InputError(r.reference.string() + ": no such reference directory (--update creates it from the frames)");
  p.reference = have_reference ? frames_dir(r.reference) : r.reference;
  p.ref_names = have_reference ? png_names(p.reference) : std::set<std::string>{};
  if (p.ref_names.empty() && !r.update)
    throw InputError(p.reference.string() + ": no PNG reference frames (empty directory; --update fills it)");
  return p;
}

// Every reference frame needs a frame; every frame needs a reference unless new ones are accepted.
void check_frames_paired(const FramePairs& p, bool update) {
  for (const auto& n : p.ref_names)
    if (!p.names.count(n))
      throw InputError((p.actual / n).string() + ": missing (the reference " + (p.reference / n).string() +
                       " has it)");
  if (!update)
    for (const auto& n : p.names)
      if (!p.ref_names.count(n))
        throw InputError((p.reference / n).string() + ": missing reference for " + (p.actual / n).string() +
                         " (--update accepts new frames)");
}

FrameResult measure_frame(const FramePairs& p, const std::string& n, const CompareThresholds& t) {
  FrameResult f;
  f.name = n;
  // Sizes from the headers first: a mismatch is reported before a large image is decoded.
  const PngHeader ha = read_png_header(p.actual / n);
  if (p.ref_names.count(n)) {
    const PngHeader hb = read_png_header(p.reference / n);
    if (ha.width != hb.width || ha.height != hb.height)
      throw InputError((p.actual / n).string() + ": " + std::to_string(ha.width) + "x" + std::to_string(ha.height) +
                       " pixels, but the reference " + (p.reference / n).string() + " has " +
                       std::to_string(hb.width) + "x" + std::to_string(hb.height));
  }
  const Image a = read_png(p.actual / n);
  f.width = a.width;
  f.height = a.height;
  if (p.ref_names.count(n)) {
    const Image b = read_png(p.reference / n);
    f.metrics = image_metrics(a, b, t.tolerance);
    f.why = threshold_failure(f.metrics, t);
  } else {
    f.is_new = true;
  }
  f.pass = f.why.empty();
  return f;
}

// Metrics only, so that bad input stops us before anything is written.
CompareResult measure_frames(const FramePairs& p, const CompareThresholds& t) {
  CompareResult res;
  for (const auto& n : p.names) {
    FrameResult f = measure_frame(p, n, t);
    res.added += f.is_new;
    res.failed += !f.pass;
    res.frames.push_back(std::move(f));
  }
  return res;
}

fs::path report_dir(const CompareRequest& r, const FramePairs& p) {
  std::error_code ec;
  const fs::path out = !r.out_dir.empty() ? r.out_dir : fs::weakly_canonical(p.actual, ec).parent_path() / "compare";
  // Diff images among the frames would be paired as frames next time.
  for (const fs::path& d : {p.actual, p.reference})
    if (fs::weakly_canonical(out, ec) == fs::weakly_canonical(d, ec))
      throw InputError(out.string() + ": reports cannot go into a frames directory (choose another --out)");
  return out;
}

void write_diff_images(const FramePairs& p, const CompareThresholds& t, CompareResult& res) {
  for (auto& f : res.frames) {
    if (f.pass) continue;
    const Image a = read_png(p.actual / f.name), b = read_png(p.reference / f.name);
    const std::string stem = fs::path(f.name).stem().string();
    f.diff = stem + "_diff.png";
    f.side = stem + "_side.png";
    const Image heat = diff_heatmap(a, b, t.tolerance);
    write_png(res.out_dir / f.diff, heat);
    write_png(res.out_dir / f.side, side_by_side(b, a, heat));
  }
}

void update_reference(const FramePairs& p, CompareResult& res) {
  ensure_directory(p.reference);
  for (const auto& f : res.frames) {
    if (!f.is_new && f.metrics.max_abs == 0) continue;  // the same pixels already
    write_file_atomic(p.reference / f.name, read_bytes(p.actual / f.name));
    ++res.updated;
  }
}

}  // namespace

CompareResult compare_frames(const CompareRequest& r) {
  check_thresholds(r.thresholds);
  const FramePairs p = find_frame_pairs(r);
  check_frames_paired(p, r.update);
  CompareResult res = measure_frames(p, r.thresholds);
  res.out_dir = report_dir(r, p);
  ensure_directory(res.out_dir);
  remove_old_diffs(res.out_dir);
  write_diff_images(p, r.thresholds, res);
  if (r.update) update_reference(p, res);
  res.json = res.out_dir / "compare.json";
  res.junit = res.out_dir / "junit.xml";
  write_file_atomic(res.json, compare_json(r, res));
  write_file_atomic(res.junit, compare_junit(r, res));
  return res;
}

}  // namespace kf::render

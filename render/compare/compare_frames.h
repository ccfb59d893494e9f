#pragma once
// keyframe compare: frames against reference frames, paired by file name, with a report for people
// (diff heat maps, compare.json) and one for CI (JUnit XML).
#include <filesystem>
#include <string>
#include <vector>

#include "render/image/image_metrics.h"

namespace kf::render {

// When a frame passes. The defaults demand identical pixels: the same scene, seed and back end give the
// same frame, so any difference is a regression.
struct CompareThresholds {
  int tolerance = 0;           // per-pixel, per-channel allowance, 8-bit levels (0..255)
  double max_fraction = 0.0;   // largest allowed fraction of pixels over `tolerance` (0..1)
  double max_mean = 255.0;     // largest allowed mean |a - b|, 8-bit levels
  double min_psnr = 0.0;       // smallest allowed PSNR in dB; 0: not checked
};

// For ray-traced frames whose sampling differs (other spp or seeds): per-pixel noise is allowed where
// it stays rare and small on average, a moved or missing object is not.
CompareThresholds noise_thresholds();

struct CompareRequest {
  std::filesystem::path actual;     // RUN_DIR (its frames/ is used) or a directory of PNG frames
  std::filesystem::path reference;  // a directory of PNG frames (or a run directory with frames/)
  std::filesystem::path out_dir;    // reports and diff images; empty: compare/ beside the actual frames
  CompareThresholds thresholds;
  bool update = false;              // afterwards copy every actual frame over its reference (adds new ones)
};

struct FrameResult {
  std::string name;  // file name, e.g. frame_0012.png
  int width = 0, height = 0;
  ImageMetrics metrics;
  bool pass = true;
  bool is_new = false;         // no reference yet (only with `update`, which adds it); neither pass nor fail
  std::string why;             // for a failing frame: which threshold it broke, with the values
  std::string diff, side;      // for a failing frame: heat map and side-by-side file names in out_dir
};

struct CompareResult {
  std::vector<FrameResult> frames;  // by name
  int failed = 0;                   // frames with a reference that break a threshold
  int added = 0;                    // frames without a reference (only with `update`)
  std::filesystem::path out_dir, json, junit;  // where the reports went
  int updated = 0;                  // references written by `update`
};

// Compares every pair; writes out_dir/compare.json, out_dir/junit.xml and, for each failing frame,
// NAME_diff.png (heat map) and NAME_side.png (reference | actual | heat map); earlier diff images there
// are removed. Throws InputError before writing anything when a directory is missing or holds no PNG, a
// frame is missing on either side (a missing reference is fine with `update`), two frames differ in size
// or a PNG cannot be read; OutputError when a report cannot be written.
CompareResult compare_frames(const CompareRequest& request);

// The per-frame verdict under `t` (empty: pass), e.g. "3.2% of pixels differ by more than 0 levels (allowed 0%)".
std::string threshold_failure(const ImageMetrics& m, const CompareThresholds& t);

}  // namespace kf::render

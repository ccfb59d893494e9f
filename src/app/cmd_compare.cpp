// keyframe compare FRAMES REFERENCE: visual regression of rendered frames against reference frames.
#include <cstdio>
#include <iostream>

#include "app/commands.h"
#include "core/error.h"
#include "render/compare/compare_frames.h"

namespace kf {

void add_compare_command(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "compare", "compare rendered frames with reference frames (paired by file name): metrics, diff images, "
                 "compare.json and JUnit XML; exit 1 when a frame fails, 3 on bad input");
  auto req = std::make_shared<render::CompareRequest>();
  auto noise = std::make_shared<bool>(false);
  auto& t = req->thresholds;
  sub->add_option("FRAMES", req->actual, "RUN_DIR (its frames/) or a directory of PNG frames")->required();
  sub->add_option("REFERENCE", req->reference, "directory of reference PNG frames")->required();
  sub->add_flag("--noise", *noise,
                "tolerate sampling noise (ray-traced frames at other spp or seeds): tolerance 48, max-fraction "
                "0.01, max-mean 3; explicit threshold options override it");
  auto* tol = sub->add_option("--tolerance", t.tolerance, "per-pixel, per-channel allowance in 8-bit levels (0..255)")
                  ->capture_default_str();
  auto* frac = sub->add_option("--max-fraction", t.max_fraction, "allowed fraction of pixels over the tolerance (0..1)")
                   ->capture_default_str();
  auto* mean = sub->add_option("--max-mean", t.max_mean, "allowed mean absolute difference in levels")->capture_default_str();
  sub->add_option("--min-psnr", t.min_psnr, "required PSNR in dB (0: not checked)")->capture_default_str();
  sub->add_option("--out", req->out_dir, "reports and diff images (default: compare/ beside the frames directory)");
  sub->add_flag("--update", req->update, "accept the frames: copy each new or changed frame over its reference");
  sub->footer("Defaults demand identical pixels (same scene, seed and back end give the same frames).\n"
              "Example:\n"
              "  keyframe render out/square\n"
              "  keyframe compare out/square refs/square --update   # the first time: keep these frames as references\n"
              "  keyframe compare out/square refs/square            # later: exit 1 and diff images on a change");
  sub->callback([=] {
    render::CompareRequest r = *req;
    if (*noise) {
      const render::CompareThresholds n = render::noise_thresholds();
      if (tol->count() == 0) r.thresholds.tolerance = n.tolerance;
      if (frac->count() == 0) r.thresholds.max_fraction = n.max_fraction;
      if (mean->count() == 0) r.thresholds.max_mean = n.max_mean;
    }
    const render::CompareResult res = render::compare_frames(r);
    for (const auto& f : res.frames)
      if (!f.pass)
        std::cout << "FAIL " << f.name << ": " << f.why << (f.diff.empty() ? "" : " -> " + (res.out_dir / f.side).string())
                  << "\n";
    std::cout << "compare: " << res.frames.size() << " frames, " << res.frames.size() - res.failed - res.added
              << " pass, " << res.failed << " fail" << (res.added ? ", " + std::to_string(res.added) + " new" : "")
              << " -> " << res.json.string() << ", " << res.junit.string() << "\n";
    if (r.update) {
      std::cout << "compare: " << res.updated << " reference frames written to " << r.reference.string() << "\n";
      return;
    }
    if (res.failed > 0)
      throw FramesDiffer("compare: " + std::to_string(res.failed) + " of " + std::to_string(res.frames.size()) +
                         " frames differ from " + r.reference.string());
  });
}

}  // namespace kf

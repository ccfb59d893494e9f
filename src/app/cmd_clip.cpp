// keyframe clip RUN_DIR: encode rendered frames into a preview clip (MP4 and/or GIF) with ffmpeg.
#include <iostream>

#include "app/commands.h"
#include "core/error.h"
#include "render/clip/make_clip.h"

namespace kf {

void add_clip_command(CLI::App& app) {
  auto* sub = app.add_subcommand("clip", "encode RUN_DIR/frames into RUN_DIR/clip.mp4 (H.264) and/or clip.gif (needs ffmpeg)");
  auto req = std::make_shared<render::ClipRequest>();
  auto gif = std::make_shared<bool>(false);
  auto gif_only = std::make_shared<bool>(false);
  sub->add_option("RUN_DIR", req->run_dir, "run directory whose frames/ were made by `keyframe render`")->required();
  sub->add_flag("--gif", *gif, "also make clip.gif (at most 640 pixels wide)");
  sub->add_flag("--gif-only", *gif_only, "make clip.gif only");
  sub->add_flag("--turntable", req->turntable, "encode frames/turntable_NNNN.png into turntable.mp4/.gif");
  sub->add_option("--fps", req->fps, "frames per second (default: the trajectory's)");
  sub->add_option("--ffmpeg", req->ffmpeg, "ffmpeg program to run")->capture_default_str();
  sub->footer("Example: keyframe render out/square && keyframe clip out/square --gif");
  sub->callback([=] {
    render::ClipRequest r = *req;
    r.gif = *gif || *gif_only;
    r.mp4 = !*gif_only;
    // Clips are optional: without ffmpeg say so plainly instead of failing half-way.
    if (render::find_program(r.ffmpeg).empty())
      throw NotReady("clip needs ffmpeg, which was not found (\"" + r.ffmpeg +
                     "\"); install it (e.g. apt-get install ffmpeg) or pass --ffmpeg PATH");
    for (const auto& f : render::make_clip(r)) std::cout << "clip -> " << f.string() << "\n";
  });
}

}  // namespace kf

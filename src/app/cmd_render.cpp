// keyframe render RUN_DIR: render a run directory's trajectory to PNG frames.
#include <iostream>
#include <regex>

#include "app/commands.h"
#include "core/error.h"
#include "render/backend.h"
#include "render/render_run.h"

namespace kf {

namespace {

void parse_size(const std::string& text, int& w, int& h) {
  std::smatch m;
  static const std::regex re(R"((\d{1,6})[xX](\d{1,6}))");
  if (!std::regex_match(text, m, re)) throw InputError("--size: expected WxH such as 1280x720, got \"" + text + "\"");
  w = std::stoi(m[1]);
  h = std::stoi(m[2]);
  if (w == 0 || h == 0) throw InputError("--size: expected a non-zero size, got \"" + text + "\"");
}

// "A:B" renders A..B-1; "A:" to the end; "A" one frame.
void parse_frames(const std::string& text, int& begin, int& end) {
  std::smatch m;
  static const std::regex re(R"((\d{1,7})?(:)?(\d{1,7})?)");
  if (text.empty() || !std::regex_match(text, m, re) || (!m[1].matched && !m[3].matched))
    throw InputError("--frames: expected A:B (frames A..B-1), A: or A, got \"" + text + "\"");
  begin = m[1].matched ? std::stoi(m[1]) : 0;
  end = m[3].matched ? std::stoi(m[3]) : (m[2].matched ? -1 : begin + 1);
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto* sub = app.add_subcommand("render", "render a run directory to PNG frames (RUN_DIR/frames/frame_NNNN.png)");
  auto req = std::make_shared<render::RenderRequest>();
  auto size = std::make_shared<std::string>();
  auto frames = std::make_shared<std::string>();
  std::string names;
  for (const auto& n : render::backend_names()) names += (names.empty() ? "" : "|") + n;
  sub->add_option("RUN_DIR", req->run_dir, "run directory holding scene.json and trajectory.bin")->required();
  sub->add_option("--backend", req->backend,
                  "renderer: osmesa = fast raster preview, embree = ray traced with soft shadows (" + names + ")")
      ->capture_default_str();
  sub->add_option("--size", *size, "image size WxH in pixels (default: the scene's render.width x height)");
  sub->add_option("--spp", req->spp, "samples per pixel (default: osmesa 4 (MSAA), embree render.samples)");
  sub->add_option("--frames", *frames, "frames A:B renders A..B-1 (default: all)");
  sub->add_option("--turntable", req->turntable,
                  "orbit the camera around the first frame in N views (frames/turntable_NNNN.png)");
  sub->footer("Frames are written whole or not at all; a bad request writes nothing.\n"
              "Example: keyframe render out/square --backend embree --size 1280x720 --spp 16");
  sub->callback([=] {
    render::RenderRequest r = *req;
    if (!size->empty()) parse_size(*size, r.width, r.height);
    if (!frames->empty()) parse_frames(*frames, r.frame_begin, r.frame_end);
    const int n = render::render_run(r);
    std::cout << "rendered " << n << " frame" << (n == 1 ? "" : "s") << " -> " << (r.run_dir / "frames").string()
              << "\n";
  });
}

}  // namespace kf

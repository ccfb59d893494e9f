#include "app/camera_options.h"

#include <iterator>

#include "app/cli_ranges.h"
#include "core/error.h"

namespace kf {

void add_camera_options(CLI::App* sub, CameraWords& words) {
  sub->add_option("--camera", words.camera,
                  "camera \"eye=X,Y,Z target=X,Y,Z [fov=DEG]\" (metres, Y up; default fov: the scene's "
                  "render.fov), instead of the scene's camera or the automatic framing")
      ->expected(1, CLI::detail::expected_max_vector_size);  // the positionals after it are taken back below
  sub->add_option("--view", words.view,
                  "a named view framing the whole scene (every particle, keyframe target and collider): " +
                      render::named_view_names() + "; from top, x runs right and z down the image");
  sub->add_option("--view-frames", words.view_frames,
                  "A:B: the automatic camera (or --view's) frames what frames A..B-1 show (the particles, a "
                  "character, the targets of keyframes among them) instead of the whole run; A: frames A "
                  "to the end. The ground and the scene's camera are not used for it");
}

std::vector<std::string> positionals_after_camera(CameraWords& words) {
  auto& w = words.camera;
  auto first = w.end();
  while (first != w.begin() && std::prev(first)->find('=') == std::string::npos) --first;
  std::vector<std::string> taken(first, w.end());
  w.erase(first, w.end());
  return taken;
}

std::string one_positional(CameraWords& words, const std::string& given, const std::string& name) {
  std::vector<std::string> all = positionals_after_camera(words);
  if (!given.empty()) all.insert(all.begin(), given);
  if (all.empty()) throw CLI::RequiredError(name);
  if (all.size() > 1) throw CLI::ExtrasError(std::vector<std::string>(all.begin() + 1, all.end()));
  return all.front();
}

render::CameraChoice camera_choice(const CameraWords& words) {
  if (words.camera.size() > 3)
    throw InputError("--camera: expected at most 3 words (eye=X,Y,Z target=X,Y,Z [fov=DEG]), got " +
                     std::to_string(words.camera.size()));
  std::string camera;
  for (const auto& w : words.camera) camera += (camera.empty() ? "" : " ") + w;
  render::CameraChoice choice = render::parse_camera_choice(camera, words.view);
  if (!words.view_frames.empty()) {
    if (choice.camera)
      throw InputError("--camera and --view-frames exclude each other: --view-frames frames the automatic camera "
                       "(give --view for its direction)");
    int begin = 0, end = -1;
    parse_frames(words.view_frames, begin, end, "--view-frames");
    choice.frames = std::make_pair(begin, end);
  }
  return choice;
}

}  // namespace kf

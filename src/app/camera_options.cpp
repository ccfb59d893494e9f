#include "app/camera_options.h"

#include <iterator>

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
  return render::parse_camera_choice(camera, words.view);
}

}  // namespace kf

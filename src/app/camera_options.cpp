#include "app/camera_options.h"

namespace kf {

void add_camera_options(CLI::App* sub, CameraWords& words) {
  sub->add_option("--camera", words.camera,
                  "camera \"eye=X,Y,Z target=X,Y,Z [fov=DEG]\" (metres, Y up; default fov: the scene's "
                  "render.fov), instead of the scene's camera or the automatic framing")
      ->expected(1, 3);
  sub->add_option("--view", words.view,
                  "a named view framing the whole scene (every particle, keyframe target and collider): " +
                      render::named_view_names() + "; from top, x runs right and z down the image");
}

render::CameraChoice camera_choice(const CameraWords& words) {
  std::string camera;
  for (const auto& w : words.camera) camera += (camera.empty() ? "" : " ") + w;
  return render::parse_camera_choice(camera, words.view);
}

}  // namespace kf

#include "render/frame_renderer.h"

#include <fstream>

#include "core/error.h"
#include "core/file_name.h"
#include "core/overloaded.h"
#include "render/frame_range_bounds.h"
#include "scene/run_name.h"

namespace kf::render {

namespace fs = std::filesystem;

RunData load_run(const fs::path& run_dir) {
  const std::string d = run_dir.string();
  if (!fs::is_directory(run_dir)) throw InputError(d + ": not a run directory (does not exist)");
  if (!fs::exists(run_dir / "scene.json")) throw InputError(d + ": not a run directory (no scene.json)");
  if (!fs::exists(run_dir / "trajectory.bin"))
    throw InputError(d + ": no trajectory.bin to render (run 'keyframe simulate' or 'keyframe run' first)");
  RunData run{load_scene(run_dir / "scene.json"), load_trajectory(run_dir / "trajectory.bin")};
  if (run.trajectory.particles != run.scene.particles())
    throw InputError(d + ": trajectory.bin has " + std::to_string(run.trajectory.particles) +
                     " particles but scene.json describes " + std::to_string(run.scene.particles()));
  if (run.trajectory.frames() != run.scene.time.frames + 1)
    throw InputError(d + "/trajectory.bin: holds " + std::to_string(run.trajectory.frames()) +
                     " frames but scene.json describes " + std::to_string(run.scene.time.frames + 1) +
                     " (frames 0.." + std::to_string(run.scene.time.frames) + ")");
  if (fs::exists(run_dir / "meshes.bin")) {
    run.meshes = load_mesh_sequence(run_dir / "meshes.bin");
    if (run.meshes->frames() != run.trajectory.frames())
      throw InputError(d + ": meshes.bin has " + std::to_string(run.meshes->frames()) +
                       " frames but trajectory.bin has " + std::to_string(run.trajectory.frames()));
  }
  // The run keeps the original scene's name beside its copy; without it the directory names the run.
  if (const auto names = read_run_name(run_dir))
    run.scene.name = names->name;
  else
    run.scene.name = fs::absolute(run_dir).lexically_normal().filename().string();
  if (run.scene.name.empty()) run.scene.name = fs::absolute(run_dir).lexically_normal().parent_path().filename().string();
  if (!file_name_problem(run.scene.name).empty()) run.scene.name = "run";
  return run;
}

FrameRenderer::FrameRenderer(const RunData& run, const std::string& backend, RenderSettings settings,
                             const CameraChoice& choice)
    : run_(run), backend_(make_backend(backend)), settings_(settings) {
  if (settings_.width == 0) settings_.width = run.scene.render.width;
  if (settings_.height == 0) settings_.height = run.scene.render.height;
  if (settings_.spp == 0) settings_.spp = default_spp(backend, run.scene.render);
  bounds_ = scene_bounds(run.scene, run.trajectory, run.meshes ? &*run.meshes : nullptr);
  const bool planar = visit_system(run.scene, Overloaded{
                                                  [](const FlockSpec&) { return true; },  // seen from above
                                                  [](const ClothSpec&) { return false; },
                                              });
  if (!choice.frames) {
    camera_ = make_camera(run.scene.render, bounds_, planar, settings_.width, settings_.height, choice);
    return;
  }
  // A range of frames is framed automatically: the scene's own camera does not follow it.
  RenderSpec framing = run.scene.render;
  framing.has_camera = false;
  const Bounds range = frame_range_bounds(run.scene, run.trajectory, run.meshes ? &*run.meshes : nullptr,
                                          choice.frames->first, choice.frames->second);
  camera_ = make_camera(framing, range, planar, settings_.width, settings_.height, choice);
}

Image FrameRenderer::render(int frame, double orbit) {
  build_frame_geometry(run_.scene, run_.trajectory, frame, bounds_, geometry_, run_.meshes ? &*run_.meshes : nullptr);
  const Camera cam = orbit == 0.0 ? camera_ : camera_.orbited(orbit);
  return backend_->render(geometry_, cam, run_.scene.render, settings_);
}

Image FrameRenderer::render_path(const std::vector<int>& frames) {
  if (!run_.scene.flock) throw InputError("figure: --overlay draws a flock's path; this run is not a flock");
  build_frame_geometry(run_.scene, run_.trajectory, frames.back(), bounds_, geometry_, run_.meshes ? &*run_.meshes : nullptr);
  add_flock_path(run_.scene, run_.trajectory, frames, geometry_);
  return backend_->render(geometry_, camera_, run_.scene.render, settings_);
}

}  // namespace kf::render

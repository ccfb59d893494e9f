#pragma once
// Loading a run directory and rendering its frames with one back end (shared by render_run and figures).
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "core/mesh_sequence.h"

#include "core/trajectory.h"
#include "render/backend.h"
#include "scene/scene.h"

namespace kf::render {

struct RunData {
  Scene scene;
  Trajectory trajectory;
  std::optional<MeshSequence> meshes;  // RUN_DIR/meshes.bin when the run has one (e.g. a character)
};

// Reads RUN_DIR/scene.json, RUN_DIR/trajectory.bin and, when present, RUN_DIR/meshes.bin (same frame
// count as the trajectory) and checks they belong together.
// Throws InputError with one line naming the directory or file.
RunData load_run(const std::filesystem::path& run_dir);

class FrameRenderer {
 public:
  // `backend`: a name from backend_names(); `settings` with 0 sizes/spp take the scene's values.
  // `choice`: --camera or --view, else the scene's camera or the automatic framing.
  FrameRenderer(const RunData& run, const std::string& backend, RenderSettings settings,
                const CameraChoice& choice = {});
  // Frame `frame` (0 <= frame < trajectory frames), camera orbited about Y by `orbit` radians.
  Image render(int frame, double orbit = 0.0);
  // A flock's path in one image: the last of `frames` with the earlier ones, trails and the centre of
  // mass added (add_flock_path). Throws InputError for a run that is not a flock.
  Image render_path(const std::vector<int>& frames);
  const RenderSettings& settings() const { return settings_; }
  const Camera& camera() const { return camera_; }

 private:
  const RunData& run_;
  std::unique_ptr<Backend> backend_;
  RenderSettings settings_;
  Bounds bounds_;
  Camera camera_;
  FrameGeometry geometry_;
};

}  // namespace kf::render

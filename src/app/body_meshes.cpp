#include "app/body_meshes.h"

#include "core/mesh_sequence.h"
#include "sim/character/scene_character.h"

namespace kf {

void write_body_meshes(const Scene& scene, int frames, const std::filesystem::path& path) {
  if (!scene.character) return;
  const CharacterSpec& spec = *scene.character;
  Character body(spec.file, character_options(spec));
  MeshSequence seq;
  seq.fps = scene.time.fps;
  const auto& tris = body.triangles();
  std::vector<uint32_t> indices(tris.data(), tris.data() + tris.size());
  seq.add_mesh("body", body.vertex_count(), std::move(indices));
  std::vector<VecX> x(1);
  for (int f = 0; f < frames; ++f) {
    pose_at_frame(body, spec, f, x[0]);
    seq.add_frame(x);
  }
  save_mesh_sequence(path, seq);
}

}  // namespace kf

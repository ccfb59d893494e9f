#include "sim/cape/skin_pin_track.h"

#include <algorithm>
#include <limits>

#include "core/error.h"
#include "scene/cloth_mesh_spec.h"
#include "sim/character/scene_character.h"

namespace kf {

SkinPinTrack::SkinPinTrack(std::vector<std::vector<Vec3>> table, const std::vector<int>& pinned, int particles,
                           double h)
    : table_(std::move(table)), slot_(particles, -1), h_(h) {
  for (size_t s = 0; s < pinned.size(); ++s) slot_[size_t(pinned[s])] = int(s);
}

void SkinPinTrack::state(int n, int particle, const Vec3& x0, Vec3& position, Vec3& velocity) const {
  const int s = slot_[size_t(particle)];
  if (s < 0) {
    position = x0;
    velocity.setZero();
    return;
  }
  const int last = int(table_.size()) - 1;
  const int a = std::clamp(n, 0, last), b = std::clamp(n + 1, 0, last);
  position = table_[size_t(a)][size_t(s)];
  velocity = (table_[size_t(b)][size_t(s)] - table_[size_t(a)][size_t(s)]) / h_;
}

std::unique_ptr<SkinPinTrack> skin_pin_track(Character& body, const CharacterSpec& character, const ClothSpec& cloth,
                                             double fps, int steps, double h) {
  if (cloth.pins.empty())
    throw InputError(character.where.substr(0, character.where.rfind('/')) +
                     "/cloth/pins: a mesh cloth on a character needs pins (the vertices that follow the body, e.g. "
                     "a region around a poncho's neck hole)");
  int begin = 0, end = body.vertex_count();
  const std::string& mesh = character.anchors.mesh;
  if (!mesh.empty()) {
    const auto& names = body.mesh_names();
    const auto it = std::find(names.begin(), names.end(), mesh);
    if (it == names.end()) throw InputError(character.where + "/anchors/mesh: no mesh named '" + mesh + "' in " + body.file());
    begin = body.mesh_vertex_begin()[size_t(it - names.begin())];
    end = body.mesh_vertex_begin()[size_t(it - names.begin()) + 1];
  }
  VecX pose;
  pose_at_frame(body, character, 0.0, pose);
  std::vector<int> vertex;
  std::vector<Vec3> offset;
  for (int p : cloth.pins) {
    const Vec3 rest = cloth_rest_position(cloth, p);
    int best = begin;
    double best_d2 = std::numeric_limits<double>::infinity();
    for (int v = begin; v < end; ++v) {
      const double d2 = (seg(pose, v) - rest).squaredNorm();
      if (d2 < best_d2) best_d2 = d2, best = v;
    }
    vertex.push_back(best);
    offset.push_back(rest - seg(pose, best));
  }
  std::vector<std::vector<Vec3>> table;
  for (int n = 0; n <= steps + 1; ++n) {
    pose_at_frame(body, character, n * h * fps, pose);
    std::vector<Vec3> at(vertex.size());
    for (size_t s = 0; s < at.size(); ++s) at[s] = seg(pose, vertex[s]) + offset[s];
    table.push_back(std::move(at));
  }
  return std::make_unique<SkinPinTrack>(std::move(table), cloth.pins, cloth.particles(), h);
}

}  // namespace kf

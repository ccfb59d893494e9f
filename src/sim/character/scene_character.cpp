#include "sim/character/scene_character.h"

namespace kf {

CharacterOptions character_options(const CharacterSpec& spec) {
  CharacterOptions o;
  o.animation = spec.animation;
  o.wrap = TimeWrap::kClamp;
  o.placement = Affine(Eigen::Translation3d(spec.offset));
  return o;
}

void pose_at_frame(Character& character, const CharacterSpec& spec, double frame, VecX& out) {
  character.pose(animation_time(spec, frame), out);
  if (spec.root.keys.empty()) return;
  // pose() placed the vertices by the offset; the root motion goes under it.
  const Affine to_frame = character_placement(spec, frame) * character.placement().inverse();
  const Mat3 r = to_frame.linear();
  const Vec3 t = to_frame.translation();
  for (Eigen::Index i = 0; i < out.size() / 3; ++i) out.segment<3>(3 * i) = r * out.segment<3>(3 * i) + t;
}

}  // namespace kf

#include "sim/character/scene_character.h"

#include <cstdio>

#include "core/error.h"
#include "core/warnings.h"

namespace kf {
namespace {

// A "time" block whose keys all hold one instant (the default before the animation played by itself) and no
// root motion: the body never moves, which a scene with a character rarely means.
void warn_if_frozen(const CharacterSpec& spec) {
  if (spec.time_keys.size() < 1 || spec.root.keys.size() > 1) return;
  for (const Vec2& k : spec.time_keys)
    if (k.y() != spec.time_keys[0].y()) return;
  char msg[512];
  std::snprintf(msg, sizeof msg,
                "%s/time: every key is at %.3g s of the animation and there is no root motion: the body stays in "
                "one pose for the whole scene (leave \"time\" out to play the animation at its own rate)",
                spec.where.c_str(), spec.time_keys[0].y());
  warn(msg);
}

}  // namespace

Character load_character(const CharacterSpec& spec, int frames) {
  try {
    Character c(spec.file, character_options(spec));
    warn_if_frozen(spec);
    if (spec.loop || c.duration() <= 0) return c;  // a looped clip never ends; a static body has none
    const double end = animation_time(spec, frames);
    // A pose held for less than a millisecond past the end is the end pose: a clip's duration and the
    // scene's frames at its fps differ by round-off (0.967 s against 29 / 30 s) without anything to say.
    constexpr double kUnseen = 1e-3;
    if (end > c.duration() + kUnseen) {
      // The frame where the animation's time passes its duration (time keys are piecewise linear).
      double last = frames;
      for (int f = 0; f <= frames; ++f)
        if (animation_time(spec, f) > c.duration() + kUnseen) {
          last = f;
          break;
        }
      char msg[512];
      std::snprintf(msg, sizeof msg,
                    "%s: the animation of %s ends at %.3g s, before the scene's last frame (frame %d at %.3g s): the "
                    "body holds its last pose from frame %.0f on (\"time\" [[frame, seconds], ...] maps frames to "
                    "the animation's seconds)",
                    spec.where.c_str(), spec.file.filename().string().c_str(), c.duration(), frames, end, last);
      warn(msg);
    }
    return c;
  } catch (const InputError& e) {
    const std::string what = e.what();
    const bool animation = what.find("animation") != std::string::npos;
    throw InputError(spec.where + (animation ? "/animation: " : "/file: ") + what);
  }
}

CharacterOptions character_options(const CharacterSpec& spec) {
  CharacterOptions o;
  o.animation = spec.animation;
  o.wrap = spec.loop ? TimeWrap::kLoop : TimeWrap::kClamp;
  o.placement = Affine(Eigen::Translation3d(spec.offset) * character_conform(spec));
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

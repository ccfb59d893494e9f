#pragma once
// The scene's character: loaded with the spec's animation and offset, posed at a scene frame (animation
// time from the spec's time keys, then the root motion), so the cape, its pins and the drawn body agree.
#include "scene/character_spec.h"
#include "sim/character/character.h"

namespace kf {

CharacterOptions character_options(const CharacterSpec& spec);

// The spec's character, loaded. An error in the file names the scene's field too ("scene.json:
// /character/animation: ..."). Warns when the scene runs past the animation's end (the body then holds its
// last pose). `frames`: the scene's frame count.
Character load_character(const CharacterSpec& spec, int frames);

// Posed vertices (3n) at a (fractional) scene frame. Allocation-free when `out` has the size already.
void pose_at_frame(Character& character, const CharacterSpec& spec, double frame, VecX& out);

}  // namespace kf

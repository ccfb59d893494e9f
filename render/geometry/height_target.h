#pragma once
// A height keyframe's target, drawn as a level outline: a rectangle at the target height around where its
// particles are (their box in x and z, padded), so the sheet is seen rising or sinking to it.
#include <vector>

#include "render/geometry/frame_geometry.h"

namespace kf::render {

// The outline's four corners, at height k.height, around the keyframe's particles (all of the `particles`
// when it lists none) at positions x (3 x particles), padded by `pad` (m) on each side.
std::vector<Vec3> height_target_outline(const ObjectiveSpec& o, const HeightKeyframe& k, const VecX& x,
                                        int particles, double pad);

}  // namespace kf::render

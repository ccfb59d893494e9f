#pragma once
// A shape keyframe's outline and holes read from SVG path data: the "svg_path" block of a shape keyframe.
#include <filesystem>
#include <vector>

#include "core/types.h"
#include "scene/params.h"

namespace kf {

// Ground loops in (x, z), metres: the outline and its holes.
struct ShapeLoops {
  std::vector<Vec2> outer;
  std::vector<std::vector<Vec2>> holes;
};

// Reads {"d": "M ... Z"} or {"file": "shape.svg"} (relative to `scene_dir`; every <path> element's d), with
// "scale" (metres per path unit, default 1), "offset" ([x, z] where the path's origin lands, default [0, 0])
// and "tolerance" (metres: how far a flattened curve may stray from the true one, default 0.01). A path
// point (px, py) lands at (x, z) = offset + scale (px, py): SVG's x right and y down are keyframe's x right
// and z toward the viewer, so the drawing appears unmirrored in the top view. The largest subpath is the
// outline and every other subpath a hole inside it (the even-odd rule, holes not overlapping). Errors are
// one line naming the file, the JSON pointer and, for the path data, the character.
ShapeLoops parse_svg_shape(Block b, const std::filesystem::path& scene_dir);

}  // namespace kf

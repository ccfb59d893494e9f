#pragma once
// The camera a command line chooses (--camera, --view on render, run and figure); it overrides the scene's
// render.camera. Seen from the named views the ground's x runs right; from "top", z runs down the image
// (toward the viewer), so a polygon written counter-clockwise in (x, z) reads clockwise from above.
#include <optional>
#include <string>
#include <utility>

#include "core/types.h"
#include "scene/render_spec.h"

namespace kf::render {

enum class NamedView { kFront, kSide, kTop, kThreeQuarter };

struct CameraChoice {
  std::optional<NamedView> view;     // framed automatically from this direction
  std::optional<CameraSpec> camera;  // eye and target as given; fov <= 0: the scene's render.fov
  // --view-frames A:B: the automatic framing covers frames A..B-1 only (B = -1: to the end), instead of
  // the whole run and the scene's camera (render/frame_range_bounds.h).
  std::optional<std::pair<int, int>> frames;
  bool empty() const { return !view && !camera && !frames; }
};

// "front|side|top|three-quarter" (the names, for help texts).
std::string named_view_names();

// --view TEXT: one of named_view_names(). Throws InputError ("--view: expected ..., got \"x\"").
NamedView parse_named_view(const std::string& text);

// --camera TEXT: "eye=X,Y,Z target=X,Y,Z [fov=DEG]" (metres, world frame, Y up; words in any order,
// separated by spaces). Up is +Y, or -Z when looking straight up or down. Throws InputError naming what
// was expected.
CameraSpec parse_camera_option(const std::string& text);

// Both options (empty strings: not given); they exclude each other. Throws InputError.
CameraChoice parse_camera_choice(const std::string& camera, const std::string& view);

// Unit vector from the target toward the eye of a named view; `up` gets its up direction.
Vec3 view_direction(NamedView view, Vec3& up);

}  // namespace kf::render

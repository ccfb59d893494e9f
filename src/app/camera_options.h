#pragma once
// --camera and --view, shared by render, run and figure.
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "render/camera_choice.h"

namespace kf {

struct CameraWords {
  std::vector<std::string> camera;  // --camera's words (quoted as one or given as up to three)
  std::string view;                 // --view
  std::string view_frames;          // --view-frames
};

// Adds --camera, --view and --view-frames to `sub`, writing into `words`.
void add_camera_options(CLI::App* sub, CameraWords& words);

// --camera takes every word up to the next option (CLI11 cannot stop at three), so the positional arguments
// written after it ("render --camera eye=0,1,4 target=0,1,0 RUN_DIR") land in its words too. Every camera word holds '=':
// the trailing words that do not are those positionals; this removes them from `words` and returns them in
// order. The commands' positionals are therefore not `required()` in CLI11, which would refuse them before
// this runs.
std::vector<std::string> positionals_after_camera(CameraWords& words);
// The one positional `name` of a command (e.g. RUN_DIR): `given` (before --camera) or the word taken back from
// --camera. Throws CLI::RequiredError when there is none and CLI::ExtrasError for more than one.
std::string one_positional(CameraWords& words, const std::string& given, const std::string& name);

// The choice the words make (positionals_after_camera first). Throws InputError (one line naming the
// option) for bad values or more than three words.
render::CameraChoice camera_choice(const CameraWords& words);

}  // namespace kf

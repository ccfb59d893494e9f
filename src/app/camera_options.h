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
};

// Adds --camera and --view to `sub`, writing into `words`.
void add_camera_options(CLI::App* sub, CameraWords& words);

// The choice the words make. Throws InputError (one line naming the option) for bad values.
render::CameraChoice camera_choice(const CameraWords& words);

}  // namespace kf

#pragma once
// A small curtain pinned along one edge and released flat: it swings down fast, and the energy check splits most
// of its steps at one step per frame. The held-schedule tests and schedule.bin's share it.
#include <string>

#include "scene/scene.h"
#include "sim/cloth/cloth_system.h"

namespace kf::test {

// `cloth_keys`: more keys of the cloth block (e.g. a cg_tolerance), starting with a comma; `keyframed`: the
// particles whose centre of mass the frame-12 keyframe names (a JSON array).
inline Scene split_curtain(const std::string& cloth_keys, const std::string& keyframed) {
  return parse_scene(R"({
    "time": {"fps": 30, "frames": 12},
    "cloth": {"nx": 8, "ny": 6, "width": 0.8, "height": 0.5, "mass": 0.2,
              "origin": [-0.4, 1.5, 0.5], "u_axis": [1, 0, 0], "v_axis": [0, 0, -1], "pins": "top_edge")" +
                         cloth_keys + R"(},
    "objectives": [{"type": "center_of_mass", "frame": 12, "particles": )" +
                         keyframed + R"(, "target": [0, 1.1, -0.1]}],
    "controls": {"kind": "per_frame", "alpha": 1e-4}
  })",
                     "curtain.json");
}

// How many steps of a split pattern were split.
inline int split_steps(const ClothSystem::StepSchedule& s) {
  int n = 0;
  for (const auto& pattern : s) n += pattern.size() > 1;
  return n;
}

}  // namespace kf::test

#pragma once
// What a flock's shape keyframe asks for, in numbers a user checks before running it (keyframe inspect):
// where the shape lies, its area, its holes and how many agents it holds at the flock's spacing.
#include <string>
#include <vector>

#include "scene/scene.h"

namespace kf {

struct ShapeSummary {
  std::string name;                  // "shape@30"
  double x_min = 0, x_max = 0, z_min = 0, z_max = 0;  // the outline's bounds on the ground, metres
  double area = 0;                   // the outline's area less its holes', m²
  int holes = 0;
  double spacing = 0;                // the flock's avoidance radius, metres
  int holds = 0;                     // agents the region holds that far apart, packed hexagonally
  int agents = 0;                    // the flock's
};

// One per shape keyframe of a flock scene, in the objectives' order (none for a cloth).
std::vector<ShapeSummary> shape_summaries(const Scene& scene);

// "shape@30: x -2 … 2 m, z -1 … 3 m, area 12.5 m², 1 hole; holds 64 agents 1.5 m apart (the flock has 200)".
std::string shape_summary_line(const ShapeSummary& s);

}  // namespace kf

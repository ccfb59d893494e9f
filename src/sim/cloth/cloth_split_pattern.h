#pragma once
// The cloth's split pattern as a System's step schedule (sim/system.h), and back: per step, the depths of its
// accepted substeps in order (ClothSystem::StepSchedule). A run directory stores it (opt/schedule_file.h).
#include <cstdint>
#include <vector>

#include "sim/cloth/cloth_system.h"

namespace kf {

kf::StepSchedule cloth_split_schedule(ClothSystem::StepSchedule steps);
// The per-step depths `schedule` holds; nullptr when it holds none of a cloth's (empty, or another system's).
const ClothSystem::StepSchedule* cloth_split_steps(const kf::StepSchedule& schedule);
// Whether `depths` is a pattern one step can take: substeps halved at most max_halvings times that tile the
// step in order (a step taken whole is {0}). An empty pattern (a step that decides afresh) is one too.
bool is_split_pattern(const std::vector<std::uint8_t>& depths, int max_halvings);

}  // namespace kf

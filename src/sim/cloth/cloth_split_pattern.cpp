#include "sim/cloth/cloth_split_pattern.h"

#include <cstddef>
#include <memory>

namespace kf {

namespace {
struct ClothSplitPattern final : StepSchedule::Pattern {
  explicit ClothSplitPattern(ClothSystem::StepSchedule s) : steps_(std::move(s)) {}
  int steps() const override { return int(steps_.size()); }
  ClothSystem::StepSchedule steps_;
};

// Walks one substep of `depth` as held_step does (cloth_split_steps.cpp): taken at this depth, or as two halves.
bool tiles(const std::vector<std::uint8_t>& depths, std::size_t& cursor, int depth, int max_halvings) {
  if (cursor >= depths.size() || depths[cursor] < depth) return false;
  if (depths[cursor] == depth) return ++cursor, true;
  return depth < max_halvings && tiles(depths, cursor, depth + 1, max_halvings) &&
         tiles(depths, cursor, depth + 1, max_halvings);
}
}  // namespace

kf::StepSchedule cloth_split_schedule(ClothSystem::StepSchedule steps) {
  return kf::StepSchedule(std::make_shared<const ClothSplitPattern>(std::move(steps)));
}

const ClothSystem::StepSchedule* cloth_split_steps(const kf::StepSchedule& schedule) {
  const auto* p = dynamic_cast<const ClothSplitPattern*>(schedule.pattern());
  return p ? &p->steps_ : nullptr;
}

bool is_split_pattern(const std::vector<std::uint8_t>& depths, int max_halvings) {
  if (depths.empty()) return true;
  std::size_t cursor = 0;
  return tiles(depths, cursor, 0, max_halvings) && cursor == depths.size();
}

}  // namespace kf

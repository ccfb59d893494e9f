#include "opt/window_extension.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/check.h"

namespace kf {

namespace {

int above_floor(const std::vector<int>& later, const WindowExtensionRule& rule) {
  int sum = 0;
  for (int m : later) sum += std::max(0, m - rule.floor_per_stage);
  return sum;
}

}  // namespace

double last_tenth_ratio(const std::vector<EvaluationRecord>& history) {
  const size_t earlier = history.size() - std::max<size_t>(1, history.size() / 10);
  double best = INFINITY, best_earlier = INFINITY;
  for (size_t i = 0; i < history.size(); ++i) {
    if (history[i].diverged || !std::isfinite(history[i].phi)) continue;
    best = std::min(best, history[i].phi);
    if (i < earlier) best_earlier = std::min(best_earlier, history[i].phi);
  }
  return std::isfinite(best_earlier) && best_earlier > 0 ? best / best_earlier : 1.0;
}

bool still_falling_at_limit(StopReason reason, const std::vector<EvaluationRecord>& history,
                            const WindowExtensionRule& rule) {
  return reason == StopReason::kEvaluationLimit && last_tenth_ratio(history) < 1.0 - rule.min_fall;
}

int borrow_cap(const std::vector<int>& later, const WindowExtensionRule& rule) {
  std::int64_t sum = 0;
  for (int m : later) sum += std::max(0, m);
  return int(std::floor(double(sum) * rule.share));
}

int chunk_to_borrow(int own, int cap_left, const std::vector<int>& later, const WindowExtensionRule& rule) {
  const int chunk = std::min({std::max(0, own), std::max(0, cap_left), above_floor(later, rule)});
  return chunk >= rule.min_chunk ? chunk : 0;
}

void lend(std::vector<int>& later, int borrowed, const WindowExtensionRule& rule) {
  const int spare = above_floor(later, rule);
  CHECK_LE(borrowed, spare);
  if (borrowed <= 0) return;
  // Each keeps floor + excess·(spare − borrowed)/spare, rounded down; the rounding gives back from the last.
  std::vector<int> took(later.size(), 0);
  int taken = 0;
  for (size_t k = 0; k < later.size(); ++k) {
    const int excess = std::max(0, later[k] - rule.floor_per_stage);
    took[k] = excess - int(std::int64_t(excess) * (spare - borrowed) / spare);
    taken += took[k];
  }
  for (size_t k = later.size(); k-- > 0 && taken > borrowed;) {
    const int back = std::min(taken - borrowed, took[k]);
    took[k] -= back;
    taken -= back;
  }
  for (size_t k = 0; k < later.size(); ++k) later[k] -= took[k];
  CHECK_EQ(taken, borrowed);
}

StageBorrowing::StageBorrowing(const std::vector<int>& limits, size_t stage, const WindowExtensionRule& rule)
    : stage_(stage), own_(stage < limits.size() ? limits[stage] : 0), cap_left_(0), rule_(rule) {
  if (stage + 1 < limits.size())
    cap_left_ = borrow_cap(std::vector<int>(limits.begin() + long(stage) + 1, limits.end()), rule);
}

int StageBorrowing::next(std::vector<int>& limits) {
  if (stage_ + 1 >= limits.size()) return 0;
  std::vector<int> later(limits.begin() + long(stage_) + 1, limits.end());
  const int chunk = chunk_to_borrow(own_, cap_left_, later, rule_);
  if (chunk == 0) return 0;
  lend(later, chunk, rule_);
  std::copy(later.begin(), later.end(), limits.begin() + long(stage_) + 1);
  limits[stage_] += chunk;
  cap_left_ -= chunk;
  borrowed_ += chunk;
  return chunk;
}

}  // namespace kf

#pragma once
// A stage still descending at its evaluation limit goes on. The plan shares the budget between stages before
// any runs, and the first window of a keyframe (its gradient the only tame one) may stop at its share while its
// best objective still falls steadily; the longer windows and the last stage that follow cannot make up for
// it, since their gradients grow with their horizon and their line searches stall where the short window's
// still descend. So a stage that is not the last, stopped by its limit while its best objective fell by more
// than `min_fall` over its last tenth of evaluations, continues from its best point with evaluations borrowed
// from the stages after it: max_evaluations stays the run's total, the stages after it share what is left,
// each keeping at least `floor_per_stage`. It borrows in chunks (its own share again at most), judged anew
// after each, and in all at most `share` of what the stages after it had: the later stages still meet the
// later keyframes. Deterministic: it reads the evaluations' objectives only, never the time.
#include <vector>

#include "opt/optimizer.h"

namespace kf {

struct WindowExtensionRule {
  bool on = true;            // whether the strategy applies it
  double min_fall = 0.005;   // the fraction the best objective must fall over the last tenth to go on
  double share = 0.5;        // at most this fraction of the later stages' evaluations is borrowed, in all
  int floor_per_stage = 12;  // every later stage keeps this many (the plan's smallest stage)
  int min_chunk = 12;        // fewer borrowed evaluations than this are not worth a fresh start
};

// The best objective at the end of `history` over the best before its last tenth (diverged evaluations
// skipped); 1 when there is nothing to compare.
double last_tenth_ratio(const std::vector<EvaluationRecord>& history);

// Whether a stage that stopped for `reason` after `history` goes on (it must also not be the last stage).
bool still_falling_at_limit(StopReason reason, const std::vector<EvaluationRecord>& history,
                            const WindowExtensionRule& rule);

// How many evaluations the next chunk borrows: at most `own` (the stage's planned share), at most what the rule's
// cap leaves (`cap_left`), and no more than the later stages (`later` their limits) can give above their floor.
// 0 when that is fewer than rule.min_chunk.
int chunk_to_borrow(int own, int cap_left, const std::vector<int>& later, const WindowExtensionRule& rule);

// The cap on what a stage may borrow in all: rule.share of the later stages' evaluations.
int borrow_cap(const std::vector<int>& later, const WindowExtensionRule& rule);

// Takes `borrowed` evaluations from the later stages' limits, each in proportion to what it has above the
// floor (the rounding's remainder from the last ones first), never below it. The sum falls by exactly
// `borrowed`, which must be at most what they have above their floors.
void lend(std::vector<int>& later, int borrowed, const WindowExtensionRule& rule);

// One stage's borrowing over a plan's stage limits: each call to next() moves one chunk from the stages after
// `stage` to it, in `limits` (their sum unchanged), and returns it; 0 once the cap or the floors leave too few.
class StageBorrowing {
 public:
  StageBorrowing(const std::vector<int>& limits, size_t stage, const WindowExtensionRule& rule);
  int next(std::vector<int>& limits);
  int borrowed() const { return borrowed_; }

 private:
  size_t stage_;
  int own_, cap_left_, borrowed_ = 0;
  WindowExtensionRule rule_;
};

}  // namespace kf

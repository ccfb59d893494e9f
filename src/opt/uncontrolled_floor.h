#pragma once
// No run ends with a keyframe worse than it was uncontrolled. Windows in keyframe order, a later keyframe's
// pull, or raised weights may leave an early keyframe farther off than no control at all left it; the run
// then ends at the best controls it evaluated whose unmet keyframes are each no worse than uncontrolled (the
// uncontrolled ones always qualify).
#include <functional>
#include <string>
#include <vector>

#include "opt/problem.h"

namespace kf {

struct FloorVerdict {
  // Index into the candidates (0: the run's result; candidates.size(): the uncontrolled controls).
  size_t chosen = 0;
  bool fell_back() const { return chosen != 0; }
  std::string why;  // one line for people when it fell back (empty otherwise)
};

// candidates[0] is the run's result, the others controls it evaluated (stage ends), all in `problem`'s
// controls at the scene's weights. `unmet` judges the problem's last rollout (every state kept) per
// keyframe. A candidate passes when it did not diverge and each keyframe it leaves unmet is no farther off
// (its term no larger) than uncontrolled; among those, the one meeting most keyframes, then the one with
// the smallest keyframe terms. The result is kept whenever it passes. `problem` is left evaluated at the
// chosen controls. `before(c)`, when given, is called before candidate c is simulated (c = candidates.size():
// the uncontrolled controls): a held step schedule is the result's, and a foreign one would move the others.
FloorVerdict uncontrolled_floor(Problem& problem, const std::vector<VecX>& candidates,
                                const std::function<std::vector<bool>(Problem&)>& unmet,
                                const std::function<void(size_t)>& before = {});

}  // namespace kf

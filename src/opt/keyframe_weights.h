#pragma once
// Keyframes are met, effort is minimised. A scene's keyframe weights and its effort weight α set a
// trade-off: at the optimum of Σ w·g + ½α‖u‖² a keyframe the controls could reach may be left outside its
// tolerance because meeting it costs more effort than its weight pays for (a flock asked to move its centre
// of mass far in few frames). So when a run ends early (converged or stalled) with a keyframe outside its
// tolerance and evaluations left, the strategy multiplies that keyframe's weight by factor^round (10, then
// 100, then 1000 ...: where the effort outweighs a keyframe many times over, a miss falls only as 1 / (1 + w s)
// with a small s, and a fixed ×10 a round would not reach it within a few rounds) and goes on from the best
// point, a few rounds at most, keeping a round only while it brings the keyframe terms (at the scene's
// weights) down. optimizer.soft_keyframes keeps the scene's weights as they are.
#include <string>
#include <vector>

namespace kf {

struct KeyframeWeightRule {
  double factor = 10.0;  // round k (1, 2, ...) multiplies a missed keyframe's weight by factor^k
  int rounds = 4;        // at most this many rounds
  int min_evaluations = 10;  // a round needs at least this many evaluations left
  // A round is kept only when the keyframe terms (at the scene's weights) fall below this fraction of what
  // they were before it; else its start is kept and the raising ends.
  double keep_below = 1.0;
};

// The weight scales after round `round` (1, 2, ...): each unmet keyframe's scale times rule.factor^round
// (scales empty: all 1).
std::vector<double> raised_weight_scales(const std::vector<double>& scales, const std::vector<bool>& unmet,
                                         const KeyframeWeightRule& rule, int round);

// Whether any keyframe is flagged unmet.
bool any_unmet(const std::vector<bool>& unmet);

// One line for the log: which keyframes (by name) are pressed on and by how much.
std::string describe_raise(const std::vector<std::string>& names, const std::vector<double>& scales,
                           const std::vector<bool>& unmet);

}  // namespace kf

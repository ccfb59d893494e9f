#pragma once
// Keyframes are met, effort is minimised. A scene's keyframe weights and its effort weight α set a
// trade-off: at the optimum of Σ w·g + ½α‖u‖² a keyframe the controls could reach may be left outside its
// tolerance because meeting it costs more effort than its weight pays for (a flock asked to move its centre
// of mass far in few frames). So when a run ends early (converged or stalled) with a keyframe outside its
// tolerance and evaluations left, the strategy multiplies that keyframe's weight by kRaiseFactor and goes on
// from the best point, a few rounds at most, keeping a round only while it brings the keyframe terms (at the
// scene's weights) down. optimizer.soft_keyframes keeps the scene's weights as they are.
#include <string>
#include <vector>

namespace kf {

struct KeyframeWeightRule {
  double factor = 10.0;  // a missed keyframe's weight is multiplied by this a round
  int rounds = 4;        // at most this many rounds (a weight at most factor^rounds times the scene's)
  int min_evaluations = 10;  // a round needs at least this many evaluations left
  // A round is kept going only while the keyframe terms (at the scene's weights) fall to at most this
  // fraction of what they were before it.
  double keep_below = 0.9;
};

// The weight scales after one more round: each unmet keyframe's scale times rule.factor (scales empty: all 1).
std::vector<double> raised_weight_scales(const std::vector<double>& scales, const std::vector<bool>& unmet,
                                         const KeyframeWeightRule& rule);

// Whether any keyframe is flagged unmet.
bool any_unmet(const std::vector<bool>& unmet);

// One line for the log: which keyframes (by name) are pressed on and by how much.
std::string describe_raise(const std::vector<std::string>& names, const std::vector<double>& scales,
                           const std::vector<bool>& unmet);

}  // namespace kf

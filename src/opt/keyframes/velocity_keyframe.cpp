// velocity: ½w Σ‖v_i − t_i‖² over the listed particles (all when none are listed). Measured by the RMS
// difference from the targets (m/s); no tolerance (never a miss).
#include <cmath>

#include "opt/keyframes/keyframe_common.h"
#include "opt/keyframes/keyframe_rules.h"

namespace kf {

template <>
struct KeyframeRules<VelocityKeyframe> {
  static std::unique_ptr<ObjectiveTerm> term(const ObjectiveSpec& s, const VelocityKeyframe& k, int particles) {
    return std::make_unique<TargetsTerm>(s, k.targets, particles, true);
  }

  static KeyframeMeasure measure(const KeyframeRun& run, const ObjectiveSpec& o, const VelocityKeyframe& k) {
    KeyframeMeasure m;
    m.error_phrase = " from its target velocities (RMS)";
    int n = 0;
    const double rms = std::sqrt(target_squared_error(o, k.targets, run.t.v[run.f], n) / n);
    m.report["rms_error"] = rms;
    m.error = format_number("%.3g m/s", rms);
    return m;
  }

  static KeyframePlacement placement(const ObjectiveSpec&, const VelocityKeyframe&) { return {}; }
};

template struct KeyframeKind<VelocityKeyframe>;

}  // namespace kf

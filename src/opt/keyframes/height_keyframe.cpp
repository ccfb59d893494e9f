// height (cloth): ½w (ȳ − h)², ȳ the mean height (y) of the listed particles (all when none are listed):
// a sheet lifted, or laid down, without saying where along the ground. Measured by the mean height
// (mean_height, metres) and its distance from the target (error, metres). Tolerance: 1 cm or 1 % of the
// sheet. A target for the particles' height fixes no point, so it places nothing for the throw fit or the
// pins' reach.
#include <cmath>

#include "opt/keyframes/keyframe_common.h"
#include "opt/keyframes/keyframe_rules.h"

namespace kf {

namespace {

double mean_height(const VecX& x, const std::vector<int>& ids) {
  long double sum = 0;
  for (int i : ids) sum += x[3 * i + 1];
  return double(sum / ids.size());
}

class HeightTerm : public ObjectiveTerm {
 public:
  HeightTerm(const ObjectiveSpec& s, const HeightKeyframe& k, int p)
      : frame_(s.frame), w_(s.weight), ids_(keyframe_members(s, p)), height_(k.height) {}
  std::string name() const override { return "height"; }
  int frame() const override { return frame_; }
  double eval(const VecX& x, const VecX&, VecX& gx, VecX&) const override {
    const double d = mean_height(x, ids_) - height_;
    const double g = w_ * d / double(ids_.size());
    for (int i : ids_) gx[3 * i + 1] += g;
    return 0.5 * w_ * d * d;
  }

 private:
  int frame_;
  double w_;
  std::vector<int> ids_;
  double height_;
};

}  // namespace

template <>
struct KeyframeRules<HeightKeyframe> {
  static std::unique_ptr<ObjectiveTerm> term(const ObjectiveSpec& s, const HeightKeyframe& k, int particles) {
    return std::make_unique<HeightTerm>(s, k, particles);
  }

  static KeyframeMeasure measure(const KeyframeRun& run, const ObjectiveSpec& o, const HeightKeyframe& k) {
    const double mean = mean_height(run.t.x[run.f], keyframe_members(o, run.t.particles));
    KeyframeMeasure m;
    m.error_phrase = " from its target height";
    m.report["mean_height"] = mean;
    m.report["error"] = std::abs(mean - k.height);
    judge_distance(m, std::abs(mean - k.height), cloth_tolerance(run.scene));
    return m;
  }

  static KeyframePlacement placement(const ObjectiveSpec&, const HeightKeyframe&) { return {}; }
};

template struct KeyframeKind<HeightKeyframe>;

}  // namespace kf

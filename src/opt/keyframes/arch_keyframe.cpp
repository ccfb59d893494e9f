// arch: ½w Σ (‖r⊥_i‖ − R)², r⊥ the offset of x_i from the cylinder's axis: cloth onto an arch. Measured by
// the RMS distance from the cylinder over all particles (rms_distance), the sheet's width and their ratio.
// Tolerance: 1 % of the width.
#include <algorithm>
#include <cmath>

#include "opt/keyframes/keyframe_common.h"
#include "opt/keyframes/keyframe_rules.h"

namespace kf {

namespace {

class ArchTerm : public ObjectiveTerm {
 public:
  ArchTerm(const ObjectiveSpec& s, const ArchKeyframe& k, int p)
      : frame_(s.frame), w_(s.weight), ids_(keyframe_members(s, p)), a_(k.axis_point), e_(k.axis), r_(k.radius) {}
  std::string name() const override { return "arch"; }
  int frame() const override { return frame_; }
  double eval(const VecX& x, const VecX&, VecX& gx, VecX&) const override {
    long double val = 0;  // extended: round-off in φ sets the floor of a finite-difference check
    for (int i : ids_) {
      const Vec3 d = seg(x, i) - a_;
      const Vec3 perp = d - d.dot(e_) * e_;
      const double len = perp.norm();
      if (len < 1e-12) continue;  // on the axis the distance is not differentiable; no pull
      const double err = len - r_;
      val += 0.5 * w_ * err * err;
      seg(gx, i) += w_ * err * perp / len;
    }
    return double(val);
  }

 private:
  int frame_;
  double w_;
  std::vector<int> ids_;
  Vec3 a_, e_;
  double r_;
};

}  // namespace

template <>
struct KeyframeRules<ArchKeyframe> {
  static std::unique_ptr<ObjectiveTerm> term(const ObjectiveSpec& s, const ArchKeyframe& k, int particles) {
    return std::make_unique<ArchTerm>(s, k, particles);
  }

  static KeyframeMeasure measure(const KeyframeRun& run, const ObjectiveSpec&, const ArchKeyframe& k) {
    const VecX& x = run.t.x[run.f];
    double sum = 0;
    const int p = int(x.size() / 3);
    for (int i = 0; i < p; ++i) {
      const Vec3 d = seg(x, i) - k.axis_point;
      const double e = (d - d.dot(k.axis) * k.axis).norm() - k.radius;
      sum += e * e;
    }
    const double width = sheet_width(run.scene, run.t.x[0]);
    KeyframeMeasure m;
    m.error_phrase = " from the arch's cylinder (RMS)";
    m.report["rms_distance"] = std::sqrt(sum / p);
    m.report["width"] = width;
    m.report["rms_over_width"] = width > 0 ? std::sqrt(sum / p) / width : 0.0;
    judge_distance(m, std::sqrt(sum / p), 0.01 * std::max(width, 1e-9));
    return m;
  }

  static KeyframePlacement placement(const ObjectiveSpec&, const ArchKeyframe&) { return {}; }
};

template struct KeyframeKind<ArchKeyframe>;

}  // namespace kf

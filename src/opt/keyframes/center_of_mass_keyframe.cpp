// center_of_mass: ½w‖x̄ − c‖², x̄ the mean position of the listed particles. Measured by the distance from
// the target (error), the length of the path through the centre-of-mass targets (path_length: from the
// start's centre of mass through every such target in frame order) and their ratio. Tolerance: cloth 1 cm
// or 1 % of the sheet; flocks 2 % of the path (at least 1 cm).
#include <algorithm>
#include <utility>

#include "opt/keyframes/keyframe_common.h"
#include "opt/keyframes/keyframe_rules.h"

namespace kf {

namespace {

class CenterOfMassTerm : public ObjectiveTerm {
 public:
  CenterOfMassTerm(const ObjectiveSpec& s, const CenterOfMassKeyframe& k, int p)
      : frame_(s.frame), w_(s.weight), ids_(keyframe_members(s, p)), target_(k.target) {}
  std::string name() const override { return "center_of_mass"; }
  int frame() const override { return frame_; }
  double eval(const VecX& x, const VecX&, VecX& gx, VecX&) const override {
    Vec3 mean = Vec3::Zero();
    for (int i : ids_) mean += seg(x, i);
    mean /= double(ids_.size());
    const Vec3 d = mean - target_;
    const Vec3 g = w_ * d / double(ids_.size());
    for (int i : ids_) seg(gx, i) += g;
    return 0.5 * w_ * d.squaredNorm();
  }

 private:
  int frame_;
  double w_;
  std::vector<int> ids_;
  Vec3 target_;
};

}  // namespace

template <>
struct KeyframeRules<CenterOfMassKeyframe> {
  static std::unique_ptr<ObjectiveTerm> term(const ObjectiveSpec& s, const CenterOfMassKeyframe& k, int particles) {
    return std::make_unique<CenterOfMassTerm>(s, k, particles);
  }

  static KeyframeMeasure measure(const KeyframeRun& run, const ObjectiveSpec& o, const CenterOfMassKeyframe& k) {
    std::vector<std::pair<int, Vec3>> pts{{0, mean_of(run.t.x[0], o.particles)}};
    for (const auto& q : run.scene.objectives)
      if (const auto* c = std::get_if<CenterOfMassKeyframe>(&q.kind)) pts.emplace_back(q.frame, c->target);
    std::stable_sort(pts.begin(), pts.end(), [](auto& a, auto& b) { return a.first < b.first; });
    double length = 0;
    for (size_t j = 1; j < pts.size(); ++j) length += (pts[j].second - pts[j - 1].second).norm();
    const double err = (mean_of(run.t.x[run.f], o.particles) - k.target).norm();
    KeyframeMeasure m;
    m.error_phrase = " from its target";
    m.report["error"] = err;
    m.report["path_length"] = length;
    m.report["error_over_path"] = length > 0 ? err / length : 0.0;
    judge_distance(m, err, run.scene.cloth ? cloth_tolerance(run.scene) : std::max(0.01, 0.02 * length));
    return m;
  }

  static KeyframePlacement placement(const ObjectiveSpec&, const CenterOfMassKeyframe& k) {
    return {KeyframePlacement::Kind::kCentroid, {k.target}};
  }
};

template struct KeyframeKind<CenterOfMassKeyframe>;

}  // namespace kf

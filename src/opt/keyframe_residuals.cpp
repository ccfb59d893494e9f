#include "opt/keyframe_residuals.h"

#include <algorithm>
#include <cmath>

#include "opt/keyframes/keyframe_common.h"
#include "opt/keyframes/keyframe_kind.h"

namespace kf {

std::vector<PlacedKeyframe> placed_keyframes(Problem& problem, const Scene& scene, bool* all_placed) {
  std::vector<PlacedKeyframe> out;
  const int particles = problem.system().particles();
  const std::vector<double>& scales = problem.weight_scales();
  if (all_placed) *all_placed = true;
  for (size_t k = 0; k < scene.objectives.size(); ++k) {
    const ObjectiveSpec& o = scene.objectives[k];
    const double scale = k < scales.size() ? scales[k] : 1.0;
    if (!(o.weight * scale > 0)) continue;
    const KeyframePlacement place = keyframe_placement(o);
    PlacedKeyframe p;
    p.objective = k;
    p.step = o.frame * problem.time().substeps;
    p.ids = keyframe_members(o, particles);
    p.targets = place.targets;
    p.centroid = place.kind == KeyframePlacement::Kind::kCentroid;
    p.root_weight = std::sqrt(o.weight * scale);
    const bool usable = place.kind != KeyframePlacement::Kind::kNone && !place.targets.empty() &&
                        (p.centroid || place.targets.size() == 1 || place.targets.size() == p.ids.size());
    if (!usable) {
      if (all_placed) *all_placed = false;
      continue;
    }
    out.push_back(std::move(p));
  }
  return out;
}

int residual_count(const std::vector<PlacedKeyframe>& placed) {
  int n = 0;
  for (const PlacedKeyframe& p : placed) n += p.rows();
  return n;
}

double keyframe_residuals(const Rollout& rollout, const std::vector<PlacedKeyframe>& placed, bool weighted, VecX& r,
                          std::vector<double>* distances) {
  int row = 0;
  double worst = 0;
  if (distances) distances->clear();
  for (const PlacedKeyframe& p : placed) {
    const VecX& x = rollout.x[size_t(p.step)];
    const double w = weighted ? p.root_weight : 1.0;
    double distance = 0;
    if (p.centroid) {
      const Vec3 d = mean_of(x, p.ids) - p.targets[0];
      r.segment<3>(row) = w * d;
      row += 3;
      distance = d.norm();
    } else {
      double sum = 0;
      for (size_t j = 0; j < p.ids.size(); ++j) {
        const Vec3 d = x.segment<3>(3 * p.ids[j]) - p.targets[p.targets.size() == 1 ? 0 : j];
        r.segment<3>(row) = w * d;
        row += 3;
        sum += d.squaredNorm();
      }
      distance = std::sqrt(sum / double(std::max<size_t>(1, p.ids.size())));
    }
    worst = std::max(worst, distance);
    if (distances) distances->push_back(distance);
  }
  return worst;
}

bool ResidualCombination::active(int n) const {
  for (const PlacedKeyframe& p : placed_)
    if (p.step == n) return true;
  return false;
}

double ResidualCombination::eval(int n, const VecX& x, const VecX&, VecX& gx, VecX&) const {
  double g = 0;
  int row = 0;
  for (const PlacedKeyframe& p : placed_) {
    if (p.step != n) {
      row += p.rows();
      continue;
    }
    if (p.centroid) {
      const double share = 1.0 / double(std::max<size_t>(1, p.ids.size()));
      const Vec3 w = w_.segment<3>(row);
      g += w.dot(mean_of(x, p.ids));
      for (int i : p.ids) gx.segment<3>(3 * i) += share * w;
    } else {
      for (size_t j = 0; j < p.ids.size(); ++j) {
        const Vec3 w = w_.segment<3>(row + 3 * long(j));
        g += w.dot(x.segment<3>(3 * p.ids[j]));
        gx.segment<3>(3 * p.ids[j]) += w;
      }
    }
    row += p.rows();
  }
  return g;
}

ResidualFlight::ResidualFlight(Problem& problem, std::vector<PlacedKeyframe> placed)
    : problem_(problem), placed_(std::move(placed)) {
  r_.resize(residual_count(placed_));
  VecX v_unused;
  problem.system().initial_state(x0_, v_unused);
  u_at_ = [this](int n) -> const VecX& {
    problem_.force_at(z_, n, u_);
    return u_;
  };
}

bool ResidualFlight::fly(const VecX& z) {
  z_ = z;
  problem_.controls().initial_velocity(z, v0_);
  RolloutOptions options;
  options.keep_for = &problem_;
  ++simulations_;
  if (!simulate(problem_.system(), x0_, v0_, problem_.time().steps(), u_at_, rollout_, options)) return false;
  worst_ = keyframe_residuals(rollout_, placed_, false, r_);
  return r_.allFinite();
}

bool ResidualFlight::transpose_times(const VecX& w, VecX& g) {
  const Controls& c = problem_.controls();
  const ResidualCombination cost(placed_, w);
  g.setZero(problem_.size());
  backward(problem_.system(), rollout_, u_at_, cost, [&](int n, const VecX& uhat) { c.add_step_gradient(n, uhat, g); },
           dx0_, dv0_, c.first_step());
  c.gather_initial_velocity(dv0_, g);
  ++adjoint_passes_;
  return g.allFinite();
}

}  // namespace kf

#include "opt/problem.h"

#include <cmath>

namespace kf {

namespace {
VecX scene_initial_velocity(System& sys) {
  VecX x, v;
  sys.initial_state(x, v);
  return v;
}
}  // namespace

Problem::Problem(const Scene& scene, const TimeSpec& time, System& sys)
    : time_(time), sys_(sys),
      controls_(scene.controls, time, sys.particles(), sys.planar(), scene_initial_velocity(sys)) {
  sys_.initial_state(x0_, v0_scene_);
  terms_at_step_.resize(time_.steps() + 1);
  for (const auto& spec : scene.objectives) {
    terms_.push_back(make_objective_term(spec, sys.particles()));
    terms_at_step_[spec.frame * time_.substeps].push_back(int(terms_.size()) - 1);
  }
}

bool Problem::active(int n) const { return !terms_at_step_[n].empty(); }

double Problem::eval(int n, const VecX& x, const VecX& v, VecX& gx, VecX& gv) const {
  double g = 0;
  for (int k : terms_at_step_[n]) g += terms_[k]->eval(x, v, gx, gv);
  return g;
}

double Problem::evaluate(const VecX& z, VecX* grad) {
  controls_.expand(z, v0_, U_);
  bool ok = simulate(sys_, x0_, v0_, U_, rollout_);
  double phi = 0;
  breakdown_.clear();
  if (ok) {
    VecX gx = VecX::Zero(sys_.dof()), gv = VecX::Zero(sys_.dof());
    for (size_t k = 0; k < terms_.size(); ++k) {
      const int n = terms_[k]->frame() * time_.substeps;
      const double g = terms_[k]->eval(rollout_.x[n], rollout_.v[n], gx, gv);
      breakdown_.emplace_back(terms_[k]->name() + "@" + std::to_string(terms_[k]->frame()), g);
      phi += g;
    }
    VecX dz_effort = VecX::Zero(size());
    const double e = controls_.effort(z, dz_effort);
    breakdown_.emplace_back("effort", e);
    phi += e;
    ok = std::isfinite(phi);
    if (ok && grad) {
      backward(sys_, rollout_, U_, *this, dU_, dx0_, dv0_);
      controls_.gather(dU_, dv0_, *grad);
      *grad += dz_effort;
      ok = grad->allFinite();
    }
  }
  diverged_ = !ok;
  if (ok) {
    have_good_ = true;
    z_good_ = z;
    phi_good_ = phi;
    return phi;
  }
  // Diverged: a smooth bowl around the last good point, far above anything a good step gives.
  const double scale = 1e6 + 1e3 * std::abs(phi_good_);
  const VecX d = have_good_ ? VecX(z - z_good_) : VecX(z);
  const double norm2 = 1.0 + std::max(1.0, z_good_.size() ? z_good_.squaredNorm() : 1.0);
  breakdown_ = {{"diverged", 1.0}};
  if (grad) *grad = (2.0 * scale / norm2) * d;
  return scale * (1.0 + d.squaredNorm() / norm2);
}

}  // namespace kf

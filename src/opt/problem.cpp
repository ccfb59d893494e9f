#include "opt/problem.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kf {

namespace {
// Initial positions, with the initial velocities written into v0.
VecX initial_positions(const System& sys, VecX& v0) {
  VecX x;
  sys.initial_state(x, v0);
  return x;
}
}  // namespace

Problem::Problem(const Scene& scene, const TimeSpec& time, System& sys)
    : time_(time), sys_(sys), x0_(initial_positions(sys, v0_scene_)),
      controls_(scene.controls, time, sys.particles(), sys.planar(), x0_, v0_scene_),
      checkpoint_every_(scene.optimizer.checkpoint_every) {
  terms_at_step_.resize(time_.steps() + 1);
  for (const auto& spec : scene.objectives) {
    terms_.push_back(make_objective_term(spec, sys.particles()));
    terms_at_step_[spec.frame * time_.substeps].push_back(int(terms_.size()) - 1);
  }
}

double Problem::control_scale() const {
  if (controls_.initial()) return 1.0;
  const VecX& m = sys_.masses();
  // A flock feels no gravity: its own steering forces are about its mass times 1 m/s^2.
  const double acceleration = sys_.planar() ? 1.0 : 9.81;
  return m.size() ? acceleration * m.mean() : 1.0;
}

void Problem::hold_forces(std::vector<VecX> forces) {
  if (forces.size() > size_t(std::max(0, controls_.first_step())))
    throw std::logic_error("Problem::hold_forces: held forces reach into the controlled steps");
  for (const VecX& u : forces)
    if (u.size() != sys_.dof()) throw std::logic_error("Problem::hold_forces: one force per degree of freedom");
  held_ = std::move(forces);
}

void Problem::force_at(const VecX& z, int n, VecX& u) const {
  if (n < controls_.first_step() && size_t(n) < held_.size()) u = held_[size_t(n)];
  else controls_.force_at(z, n, u);
}

bool Problem::active(int n) const { return !terms_at_step_[n].empty(); }

void Problem::set_weight_scales(std::vector<double> scales) {
  if (!scales.empty() && scales.size() != terms_.size())
    throw std::logic_error("Problem::set_weight_scales: one scale per keyframe term");
  for (double s : scales)
    if (!(s >= 0) || !std::isfinite(s)) throw std::logic_error("Problem::set_weight_scales: scales must not be negative");
  scales_ = std::move(scales);
  if (std::all_of(scales_.begin(), scales_.end(), [](double s) { return s == 1.0; })) scales_.clear();
}

double Problem::eval_term(int k, const VecX& x, const VecX& v, VecX& gx, VecX& gv) const {
  if (scales_.empty() || scales_[k] == 1.0) return terms_[k]->eval(x, v, gx, gv);
  if (scales_[k] == 0.0) return 0.0;  // a keyframe this stage is not judged on
  gx_term_.setZero(x.size());  // sized once: the vectors are kept between calls
  gv_term_.setZero(v.size());
  const double g = terms_[k]->eval(x, v, gx_term_, gv_term_);
  gx += scales_[k] * gx_term_;
  gv += scales_[k] * gv_term_;
  return scales_[k] * g;
}

double Problem::eval(int n, const VecX& x, const VecX& v, VecX& gx, VecX& gv) const {
  double g = 0;
  for (int k : terms_at_step_[n]) g += eval_term(k, x, v, gx, gv);
  return g;
}

double Problem::evaluate(const VecX& z, VecX* grad) {
  controls_.initial_velocity(z, v0_);
  // Forces are made one step at a time, so per-frame controls are never expanded per step.
  const StepControl u_at = [&](int n) -> const VecX& {
    if (n < controls_.first_step() && size_t(n) < held_.size()) return held_[size_t(n)];
    controls_.force_at(z, n, u_);
    return u_;
  };
  RolloutOptions options;
  options.checkpoint_every = grad ? checkpoint_every_ : 0;
  options.memory_budget = grad ? memory_budget_ : 0;
  options.keep_for = this;
  options.tape = grad != nullptr;  // a value alone needs no tape: a checkpointed run's last simulation stays small
  bool ok = simulate(sys_, x0_, v0_, time_.steps(), u_at, rollout_, options);
  long double phi = 0;  // extended, like each term's sum: φ's round-off is a gradient check's floor
  breakdown_.clear();
  if (ok) ok = objective_of_rollout(z, grad, u_at, phi);
  diverged_ = !ok;
  if (ok) {
    have_good_ = true;
    z_good_ = z;
    phi_good_ = double(phi);
    return double(phi);
  }
  return diverged_objective(z, grad);
}

bool Problem::objective_of_rollout(const VecX& z, VecX* grad, const StepControl& u_at, long double& phi) {
  VecX gx = VecX::Zero(sys_.dof()), gv = VecX::Zero(sys_.dof());
  for (size_t k = 0; k < terms_.size(); ++k) {
    const int n = terms_[k]->frame() * time_.substeps;
    const double g = eval_term(int(k), rollout_.x[n], rollout_.v[n], gx, gv);
    breakdown_.emplace_back(terms_[k]->name() + "@" + std::to_string(terms_[k]->frame()), g);
    phi += g;
  }
  dz_effort_.setZero(size());
  const double e = controls_.effort(z, dz_effort_);
  breakdown_.emplace_back("effort", e);
  phi += e;
  if (!std::isfinite(phi)) return false;
  if (!grad) return true;
  grad->setZero(size());
  backward(sys_, rollout_, u_at, *this, [&](int n, const VecX& uhat) { controls_.add_step_gradient(n, uhat, *grad); },
           dx0_, dv0_, controls_.first_step());
  controls_.gather_initial_velocity(dv0_, *grad);
  *grad += dz_effort_;
  return grad->allFinite();
}

double Problem::diverged_objective(const VecX& z, VecX* grad) {
  // A smooth bowl around the last good point, far above anything a good step gives. Every quantity is
  // formed so that huge trial controls (or a huge last good point) cannot overflow it.
  const double scale = 1e6 + 1e3 * std::min(std::abs(phi_good_), 1e250);
  const VecX d = have_good_ ? VecX(z - z_good_) : VecX(z);
  const double r0 = std::hypot(1.0, std::max(1.0, z_good_.size() ? z_good_.stableNorm() : 1.0));
  breakdown_ = {{"diverged", 1.0}};
  const double t = d.allFinite() ? d.stableNorm() / r0 : INFINITY;  // distance in units of r0
  constexpr double kT = 1e6;
  if (t <= kT) {
    if (grad) *grad = (2.0 * scale) * ((d / r0) / r0);
    return scale * (1.0 + t * t);
  }
  // Beyond t = kT the bowl grows as log t (value and slope continuous at kT), so it never overflows.
  if (grad) {
    if (std::isfinite(t)) *grad = (2.0 * scale * kT * kT) * ((((d / t) / t) / r0) / r0);
    else grad->setZero(z.size());
  }
  return scale * (1.0 + kT * kT * (1.0 + 2.0 * std::log(std::min(t, 1e300) / kT)));
}

}  // namespace kf

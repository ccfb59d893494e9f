#include "opt/few_variable_fit.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <utility>

#include "opt/keyframes/keyframe_common.h"

namespace kf {

const char* fit_stop_name(FitStop s) {
  switch (s) {
    case FitStop::kReached: return "reached";
    case FitStop::kConverged: return "converged";
    case FitStop::kStalled: return "stalled";
    case FitStop::kBudget: return "budget";
    case FitStop::kInterrupted: return "interrupted";
    case FitStop::kNoResiduals: return "nothing placed";
    case FitStop::kDiverged: return "start diverged";
    case FitStop::kBounded: return "bounded";
    case FitStop::kNotPaying: return "not paying";
  }
  return "?";
}

FewVariableFit::FewVariableFit(Problem& problem, const Scene& scene, int variables, ControlsOf controls_of,
                               const FewFitOptions& o)
    : problem_(problem),
      placed_(placed_keyframes(problem, scene)),
      n_(variables),
      controls_of_(std::move(controls_of)),
      o_(o),
      budget_(o.max_simulations),
      stop_(o.stop) {
  tolerance_ = cloth_tolerance(scene);
  reach_ = o.reach_share * tolerance_;
  r_.resize(residual_count(placed_));
  trial_.resize(r_.size());
  jacobian_.resize(r_.size(), n_);
}

FitStop FewVariableFit::fit(VecX& y, double& cost, double& worst, double& start_cost) {
  const FitStop stop = steps(y, cost, worst, start_cost);
  // Ended short of the keyframes without the paying share: the paying test at the fit's end as at its steps.
  const bool ended = stop == FitStop::kConverged || stop == FitStop::kStalled || stop == FitStop::kBudget;
  return o_.paying_steps > 0 && ended && cost > o_.paying_share * start_cost ? FitStop::kNotPaying : stop;
}

FitStop FewVariableFit::steps(VecX& y, double& cost, double& worst, double& start_cost) {
  if (!fly(y, r_, worst)) return FitStop::kDiverged;
  cost = start_cost = 0.5 * r_.squaredNorm();
  costs_.assign(1, cost);
  double lambda = -1, nu = 2;
  for (;;) {
    if (worst <= reach_) return FitStop::kReached;
    if (o_.paying_steps > 0 && int(costs_.size()) > o_.paying_steps && cost > o_.paying_share * start_cost)
      return FitStop::kNotPaying;
    if (!jacobian(y)) return stopped();
    const Eigen::MatrixXd jtj = jacobian_.transpose() * jacobian_;
    const VecX jtr = jacobian_.transpose() * r_;
    if (lambda < 0) lambda = 1e-3 * std::max(1e-300, jtj.diagonal().maxCoeff());
    for (;;) {
      Eigen::MatrixXd a = jtj;
      a.diagonal().array() += lambda;
      VecX step = -a.ldlt().solve(jtr);
      if (!step.allFinite()) return FitStop::kStalled;
      if (step.norm() > o_.max_step) step *= o_.max_step / step.norm();
      VecX trial_y = y;
      for (int d = 0; d < n_; ++d) trial_y[d] += step[d] / scale(d);
      // A step out of the ball: the fit heads for a point the caller does not want (one found inside after
      // such a step is another basin's, poncho-lift's lift).
      if (o_.max_norm > 0 && scaled_norm(trial_y) > o_.max_norm) return FitStop::kBounded;
      const double predicted = -(step.dot(jtr) + 0.5 * step.dot(jtj * step));
      double trial_worst = 0;
      if (out_of_budget()) return stopped();
      const bool flew = fly(trial_y, trial_, trial_worst);
      const double trial_cost = flew ? 0.5 * trial_.squaredNorm() : INFINITY;
      if (trial_cost < cost) {
        const double gain = predicted > 0 ? (cost - trial_cost) / predicted : 0;
        lambda *= std::max(1.0 / 3, 1 - std::pow(2 * gain - 1, 3));
        nu = 2;
        const bool negligible = cost - trial_cost <= 1e-12 * cost;
        y = trial_y;
        cost = trial_cost;
        worst = trial_worst;
        r_.swap(trial_);
        costs_.push_back(cost);
        if (negligible) return worst <= reach_ ? FitStop::kReached : FitStop::kConverged;
        break;
      }
      lambda *= nu;
      nu *= 2;
      if (step.norm() < 1e-12 || lambda > 1e12 * std::max(1e-300, jtj.diagonal().maxCoeff())) return FitStop::kStalled;
    }
  }
}

double FewVariableFit::scaled_norm(const VecX& y) const {
  double sum = 0;
  for (int d = 0; d < n_; ++d) sum += std::pow(y[d] * scale(d), 2);
  return std::sqrt(sum);
}

bool FewVariableFit::fly(const VecX& y, VecX& r, double& worst) {
  controls_of_(y, z_);
  problem_.evaluate(z_, nullptr);
  ++simulated_;
  if (problem_.last_diverged()) return false;
  worst = keyframe_residuals(problem_.rollout(), placed_, true, r);
  return r.allFinite();
}

// Central differences with the step decisions of y's flight (the last one) held: a split step that comes and
// goes between the two sides of a difference is a jump, not a slope.
bool FewVariableFit::jacobian(const VecX& y) {
  System& sys = problem_.system();
  sys.hold_step_schedule(sys.step_schedule());
  const double h = o_.difference_step;
  double unused;
  bool ok = true;
  for (int d = 0; d < n_ && ok; ++d) {
    VecX yp = y, ym = y;
    yp[d] += h / scale(d);
    ym[d] -= h / scale(d);
    ok = !out_of_budget() && fly(yp, trial_, unused);
    if (!ok) break;
    jacobian_.col(d) = trial_;
    ok = !out_of_budget() && fly(ym, trial_, unused);
    if (ok) jacobian_.col(d) = (jacobian_.col(d) - trial_) / (2 * h);
  }
  sys.release_step_schedule();
  return ok;
}

}  // namespace kf

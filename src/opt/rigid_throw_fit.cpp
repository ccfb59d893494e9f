#include "opt/rigid_throw_fit.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "opt/keyframes/keyframe_common.h"
#include "opt/keyframe_residuals.h"
#include "opt/keyframes/keyframe_kind.h"

namespace kf {

namespace {

// The sheet's RMS radius about its centroid: ω times it is a rim speed, so (Δv, ω · radius) are alike.
double sheet_radius(Problem& problem) {
  VecX x0, v0;
  problem.system().initial_state(x0, v0);
  const int p = int(x0.size() / 3);
  std::vector<int> all(static_cast<size_t>(p));
  for (int i = 0; i < p; ++i) all[size_t(i)] = i;
  const Vec3 c = mean_of(x0, all);
  double s = 0;
  for (int i = 0; i < p; ++i) s += (x0.segment<3>(3 * i) - c).squaredNorm();
  return std::max(1e-3, std::sqrt(s / std::max(1, p)));
}

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

class RigidFitter {
 public:
  RigidFitter(Problem& problem, const Scene& scene, const RigidFitOptions& o)
      : problem_(problem), placed_(placed_keyframes(problem, scene)), budget_(o.max_simulations), stop_(o.stop) {
    radius_ = sheet_radius(problem);
    tolerance_ = cloth_tolerance(scene);
    reach_ = o.reach_share * tolerance_;
    r_.resize(residual_count(placed_));
    trial_.resize(r_.size());
    jacobian_.resize(r_.size(), 6);
  }
  bool empty() const { return placed_.empty(); }
  int simulated() const { return simulated_; }
  double tolerance() const { return tolerance_; }

  // Levenberg–Marquardt from z (in and out: the best point reached), its cost and worst distance out.
  RigidFitStop fit(VecX& z, double& cost, double& worst, double& start_cost) {
    if (!fly(z, r_, worst)) return RigidFitStop::kDiverged;
    cost = start_cost = 0.5 * r_.squaredNorm();
    double lambda = -1, nu = 2;
    for (;;) {
      if (worst <= reach_) return RigidFitStop::kReached;
      if (!jacobian(z)) return stopped();
      const Mat6 jtj = jacobian_.transpose() * jacobian_;
      const Vec6 jtr = jacobian_.transpose() * r_;
      if (lambda < 0) lambda = 1e-3 * std::max(1e-300, jtj.diagonal().maxCoeff());
      for (;;) {
        // The damped step in scaled variables (Δv, ω · radius), at most 2 m/s of rim or centre speed.
        Mat6 a = jtj;
        a.diagonal().array() += lambda;
        Vec6 step = -a.ldlt().solve(jtr);
        if (!step.allFinite()) return RigidFitStop::kStalled;
        if (step.norm() > 2.0) step *= 2.0 / step.norm();
        const double predicted = -(step.dot(jtr) + 0.5 * step.dot(jtj * step));
        VecX trial_z = z;
        trial_z.head<3>() += step.head<3>();
        trial_z.tail<3>() += step.tail<3>() / radius_;
        double trial_worst = 0;
        if (out_of_budget()) return stopped();
        const bool flew = fly(trial_z, trial_, trial_worst);
        const double trial_cost = flew ? 0.5 * trial_.squaredNorm() : INFINITY;
        if (trial_cost < cost) {
          const double gain = predicted > 0 ? (cost - trial_cost) / predicted : 0;
          lambda *= std::max(1.0 / 3, 1 - std::pow(2 * gain - 1, 3));
          nu = 2;
          const bool negligible = cost - trial_cost <= 1e-12 * cost;
          z = trial_z;
          cost = trial_cost;
          worst = trial_worst;
          r_.swap(trial_);
          if (negligible) return worst <= reach_ ? RigidFitStop::kReached : RigidFitStop::kConverged;
          break;
        }
        lambda *= nu;
        nu *= 2;
        if (step.norm() < 1e-12 || lambda > 1e12 * std::max(1e-300, jtj.diagonal().maxCoeff()))
          return RigidFitStop::kStalled;
      }
    }
  }

 private:
  bool out_of_budget() const { return simulated_ >= budget_ || (stop_ && stop_->load()); }
  RigidFitStop stopped() const { return stop_ && stop_->load() ? RigidFitStop::kInterrupted : RigidFitStop::kBudget; }

  bool fly(const VecX& z, VecX& r, double& worst) {
    problem_.evaluate(z, nullptr);
    ++simulated_;
    if (problem_.last_diverged()) return false;
    worst = keyframe_residuals(problem_.rollout(), placed_, true, r);
    return r.allFinite();
  }

  // Central differences in the scaled variables (a millimetre per second of centre or rim speed), with the
  // step decisions of z's flight (the last one) held: a split step that comes and goes between the two
  // sides of a difference is a jump, not a slope.
  bool jacobian(const VecX& z) {
    System& sys = problem_.system();
    sys.hold_step_schedule(sys.step_schedule());
    const bool ok = differences(z);
    sys.release_step_schedule();
    return ok;
  }
  bool differences(const VecX& z) {
    constexpr double kStep = 1e-3;
    double unused;
    for (int d = 0; d < 6; ++d) {
      const double h = d < 3 ? kStep : kStep / radius_;
      VecX zp = z, zm = z;
      zp[d] += h;
      zm[d] -= h;
      if (out_of_budget() || !fly(zp, trial_, unused)) return false;
      jacobian_.col(d) = trial_;
      if (out_of_budget() || !fly(zm, trial_, unused)) return false;
      jacobian_.col(d) = (jacobian_.col(d) - trial_) / (2 * kStep);
    }
    return true;
  }

  Problem& problem_;
  std::vector<PlacedKeyframe> placed_;
  int budget_;
  const std::atomic<bool>* stop_;
  double radius_ = 1, tolerance_ = 0.01, reach_ = 0;
  int simulated_ = 0;
  VecX r_, trial_;
  Eigen::MatrixXd jacobian_;
};

}  // namespace

RigidThrowFit fit_rigid_throw(Problem& problem, const Scene& scene, const std::vector<VecX>& starts,
                              const RigidFitOptions& options) {
  if (problem.controls().kind() != ControlKind::kInitialRigidVelocity)
    throw std::logic_error("fit_rigid_throw: the problem's controls are not a rigid throw");
  RigidThrowFit best;
  RigidFitter fitter(problem, scene, options);
  if (fitter.empty()) {
    best.stops.push_back(RigidFitStop::kNoResiduals);
    return best;
  }
  best.cost = INFINITY;
  for (const VecX& start : starts) {
    if (fitter.simulated() >= options.max_simulations || (options.stop && options.stop->load())) break;
    VecX z = start;
    double cost = INFINITY, worst = INFINITY, start_cost = INFINITY;
    const RigidFitStop why = fitter.fit(z, cost, worst, start_cost);
    ++best.starts;
    best.stops.push_back(why);
    best.start_costs.push_back(start_cost);
    best.end_costs.push_back(cost);
    if (cost < best.cost) {
      best.z = z;
      best.cost = cost;
      best.worst_miss = worst / fitter.tolerance();
    }
    if (why == RigidFitStop::kReached) break;
  }
  best.simulated = fitter.simulated();
  if (!std::isfinite(best.cost)) best.z = VecX();
  return best;
}

namespace {

const char* stop_name(RigidFitStop s) {
  switch (s) {
    case RigidFitStop::kReached: return "reached";
    case RigidFitStop::kConverged: return "converged";
    case RigidFitStop::kStalled: return "stalled";
    case RigidFitStop::kBudget: return "budget";
    case RigidFitStop::kInterrupted: return "interrupted";
    case RigidFitStop::kNoResiduals: return "nothing placed";
    case RigidFitStop::kDiverged: return "start diverged";
  }
  return "?";
}

}  // namespace

void absorb(RigidThrowFit& into, const RigidThrowFit& more) {
  into.simulated += more.simulated;
  into.starts += more.starts;
  into.stops.insert(into.stops.end(), more.stops.begin(), more.stops.end());
  into.start_costs.insert(into.start_costs.end(), more.start_costs.begin(), more.start_costs.end());
  into.end_costs.insert(into.end_costs.end(), more.end_costs.begin(), more.end_costs.end());
  if (more.z.size() == 6 && (into.z.size() != 6 || more.cost < into.cost)) {
    into.z = more.z;
    into.cost = more.cost;
    into.worst_miss = more.worst_miss;
  }
}

std::string describe(const RigidThrowFit& fit) {
  std::ostringstream os;
  os << std::setprecision(3) << "rigid Levenberg-Marquardt from " << fit.starts << " start" << (fit.starts == 1 ? "" : "s")
     << " (";
  for (size_t k = 0; k < fit.stops.size(); ++k) os << (k ? ", " : "") << stop_name(fit.stops[k]);
  os << "), " << fit.simulated << " flights";
  if (fit.z.size() == 6) os << ", worst keyframe " << fit.worst_miss << " tolerances";
  return os.str();
}

}  // namespace kf

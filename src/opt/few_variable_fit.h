#pragma once
// Levenberg–Marquardt on a few variables y that set a problem's controls (a rigid throw's six, a uniform push's
// three). A keyframe problem has few residuals (a centre of mass is three numbers): their Jacobian in y by
// central differences (2n flights, no adjoint, the step decisions of the point's flight held) gives a
// Gauss–Newton step that reaches a zero-residual solution in a few iterations where L-BFGS on all controls,
// seeing one scalar, crawls along a narrow valley. Callers: opt/rigid_throw_fit.h, opt/uniform_push.h.
#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "core/types.h"
#include "opt/keyframe_residuals.h"
#include "opt/problem.h"
#include "scene/scene.h"

namespace kf {

// Why a fit from one start ended.
enum class FitStop {
  kReached,      // every placed keyframe within FewFitOptions::reach_share of its tolerance
  kConverged,    // a step changed the residuals by (relatively) nothing: a minimum, maybe a local one
  kStalled,      // the damping grew past any useful step: no step from here lowers the residuals
  kBudget,       // the simulations allowed were spent
  kInterrupted,  // *stop was set
  kNoResiduals,  // no keyframe places the sheet's particles (nothing to fit)
  kDiverged,     // the start itself diverged
  kBounded,      // a trial step would leave FewFitOptions::max_norm's ball: the fit heads past it
  kNotPaying,    // FewFitOptions::paying_steps steps in, the cost was not down to paying_share of the start's
};

const char* fit_stop_name(FitStop s);

struct FewFitOptions {
  int max_simulations = 200;
  // A start is done when every placed keyframe is within this share of its tolerance (0: fit to convergence).
  double reach_share = 0.01;
  // The steps are taken in scaled variables y_d · scales[d] (empty: all 1), so that variables of different units
  // are alike (a rigid throw's spin times the sheet's radius is a rim speed, like its velocity).
  VecX scales;
  double max_step = 2.0;          // the longest damped step, scaled
  double difference_step = 1e-3;  // the central differences' step, scaled
  const std::atomic<bool>* stop = nullptr;  // set: the fit ends after the flight under way
  // The scaled variables stay in the ball of this radius (0: no bound): a trial step that would leave it ends
  // the fit (kBounded) without flying, at the best point reached.
  double max_norm = 0;
  // After this many accepted steps (0: never) the cost must be at most paying_share of the start's, or the fit
  // ends (kNotPaying): a fit that has not fallen by a clear factor in its first steps rarely does later.
  // A fit that ends short of the keyframes (converged, stalled, out of flights) above that share is not paying
  // either.
  int paying_steps = 0;
  double paying_share = 0.5;
};

// y (n) -> the problem's controls z (resized by the callee).
using ControlsOf = std::function<void(const VecX& y, VecX& z)>;

class FewVariableFit {
 public:
  // The keyframes `problem` places at its weight scales (placed_keyframes) are the residuals.
  FewVariableFit(Problem& problem, const Scene& scene, int variables, ControlsOf controls_of, const FewFitOptions& o);
  bool empty() const { return placed_.empty(); }
  int simulated() const { return simulated_; }
  double tolerance() const { return tolerance_; }
  // ½‖r‖² at the start and after each accepted step (the log's trace of a fit).
  const std::vector<double>& costs() const { return costs_; }
  bool out_of_budget() const { return simulated_ >= budget_ || (stop_ && stop_->load()); }

  // Levenberg–Marquardt from y (in and out: the best point reached), its cost ½‖r‖² (weighted as φ weighs the
  // keyframes) and worst keyframe distance (m) out.
  FitStop fit(VecX& y, double& cost, double& worst, double& start_cost);

 private:
  FitStop steps(VecX& y, double& cost, double& worst, double& start_cost);  // fit() before its end's paying test
  FitStop stopped() const { return stop_ && stop_->load() ? FitStop::kInterrupted : FitStop::kBudget; }
  bool fly(const VecX& y, VecX& r, double& worst);
  bool jacobian(const VecX& y);
  double scale(int d) const { return o_.scales.size() ? o_.scales[d] : 1.0; }
  double scaled_norm(const VecX& y) const;

  Problem& problem_;
  std::vector<PlacedKeyframe> placed_;
  int n_;
  ControlsOf controls_of_;
  FewFitOptions o_;
  int budget_;
  const std::atomic<bool>* stop_;
  double tolerance_ = 0.01, reach_ = 0;
  int simulated_ = 0;
  VecX r_, trial_, z_;
  std::vector<double> costs_;
  Eigen::MatrixXd jacobian_;
};

}  // namespace kf

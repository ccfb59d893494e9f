#include "opt/keyframe_projection.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "opt/keyframe_residuals.h"
#include "opt/projection_metric.h"
#include "opt/residual_sketch.h"
#include "opt/keyframes/keyframe_common.h"

namespace kf {

namespace {

// The Levenberg–Marquardt damping and, when backtracking, the trust region on the largest change of one control.
struct Damping {
  double mu = -1, nu = 2, cap = 0;
  void taken(double gain, double step, double max_step, bool backtrack) {
    mu *= std::max(1.0 / 3, 1 - std::pow(2 * gain - 1, 3));
    nu = 2;
    if (backtrack && gain > 0.75) cap = std::min(max_step, std::max(cap, 2 * step));
  }
  void refused(double step, bool backtrack) {
    if (backtrack) {
      cap = step / 3;
      mu *= 2;
    } else {
      mu *= nu;
      nu *= 2;
    }
  }
};

class Projector {
 public:
  Projector(Problem& problem, std::vector<PlacedKeyframe> placed, double tolerance, const ProjectionOptions& o)
      : flight_(problem, std::move(placed)),
        tolerance_(tolerance),
        o_(o),
        max_step_(o.max_step * problem.control_scale()),
        x0_(initial_positions(problem)),
        metric_(problem.controls(), x0_, problem.system().planar(), o.smooth),
        sketched_(o.sketch && sketched(flight_.placed())) {}

  void run(VecX z, KeyframeProjection& out) {
    if (!flight_.fly(z)) return finish(out, ProjectionStop::kDiverged);
    VecX r = flight_.residuals();
    double worst = flight_.worst();
    out.z = z;
    out.start_worst = out.worst = worst / tolerance_;
    if (out.start_worst > o_.near_limit) return finish(out, ProjectionStop::kFar);
    double cost = 0.5 * r.squaredNorm();
    Damping d;
    d.cap = max_step_;
    const double reach = o_.reach_share * tolerance_;
    for (;;) {
      if (worst <= reach) return finish(out, ProjectionStop::kReached);
      // The last flight is z's: a refused trial is always followed by another until one is taken.
      if (!jacobian(r)) return finish(out, stopped());
      ++out.iterations;
      // r lies in the sketch's rows: ‖S r‖ = ‖r‖, and the model below is of the whole cost.
      const VecX rs = sketched_ ? VecX(sketch_ * r) : r;
      // In the kernel's metric: the step is −K Jᵀ y, so the linearised residuals change by −J K Jᵀ y.
      const Eigen::MatrixXd jk = metric_.times_kernel(jacobian_);
      const Eigen::MatrixXd a = jk * jacobian_.transpose();
      const double scale = std::max(1e-300, a.diagonal().maxCoeff());
      if (d.mu < 0) d.mu = 1e-6 * scale;
      for (;;) {
        Eigen::MatrixXd damped = a;
        damped.diagonal().array() += d.mu;
        const VecX y = damped.ldlt().solve(rs);
        VecX dz = -(jk.transpose() * y);
        if (!dz.allFinite()) return finish(out, ProjectionStop::kStalled);
        const double largest = dz.cwiseAbs().maxCoeff();
        const double shrink = largest > d.cap ? d.cap / largest : 1.0;
        dz *= shrink;
        // The linearised residuals after the step: S r − shrink · A y.
        const double predicted = cost - 0.5 * (rs - shrink * (a * y)).squaredNorm();
        if (out_of_budget()) return finish(out, stopped());
        const VecX trial_z = z + dz;
        const bool flew = flight_.fly(trial_z);
        const double trial_cost = flew ? 0.5 * flight_.residuals().squaredNorm() : INFINITY;
        if (std::isnan(out.first_gain)) out.first_gain = predicted > 0 ? (cost - trial_cost) / predicted : -INFINITY;
        if (trial_cost < cost) {
          d.taken(predicted > 0 ? (cost - trial_cost) / predicted : 0, largest * shrink, max_step_, o_.backtrack);
          const bool negligible = cost - trial_cost <= 1e-12 * cost;
          z = trial_z;
          cost = trial_cost;
          r = flight_.residuals();
          worst = flight_.worst();
          if (worst / tolerance_ < out.worst) {  // the point with the nearest worst keyframe, not the lowest ½‖r‖²
            out.z = z;
            out.worst = worst / tolerance_;
          }
          if (negligible && worst > reach) return finish(out, ProjectionStop::kStalled);
          break;
        }
        ++out.refused;
        d.refused(largest * shrink, o_.backtrack);
        if (largest * shrink < 1e-12 || d.mu > 1e12 * scale) return finish(out, ProjectionStop::kStalled);
      }
    }
  }

 private:
  void finish(KeyframeProjection& out, ProjectionStop why) const {
    out.stop = why;
    out.simulations = flight_.simulations();
    out.adjoint_passes = flight_.adjoint_passes();
  }
  int passes() const { return flight_.simulations() + flight_.adjoint_passes(); }
  bool out_of_budget() const { return passes() >= o_.max_passes || (o_.stop && o_.stop->load()); }
  ProjectionStop stopped() const {
    return o_.stop && o_.stop->load() ? ProjectionStop::kInterrupted : ProjectionStop::kBudget;
  }

  static VecX initial_positions(Problem& problem) {
    VecX x0, v0;
    problem.system().initial_state(x0, v0);
    return x0;
  }

  // One adjoint pass per row of the sketch (opt/residual_sketch.h; every residual when nothing is sketched)
  // over the last flight, whose residuals are r: the rows of S dr/dz.
  bool jacobian(const VecX& r) {
    sketch_ = sketched_ ? residual_sketch(flight_.placed(), x0_, r) : Eigen::MatrixXd::Identity(r.size(), r.size());
    VecX w, row;
    for (long k = 0; k < sketch_.rows(); ++k) {
      if (out_of_budget()) return false;
      w = sketch_.row(k).transpose();
      if (!flight_.transpose_times(w, row)) return false;
      if (k == 0) jacobian_.resize(sketch_.rows(), row.size());
      jacobian_.row(k) = row.transpose();
    }
    return true;
  }

  ResidualFlight flight_;
  double tolerance_;
  ProjectionOptions o_;
  double max_step_;
  VecX x0_;
  ProjectionMetric metric_;
  bool sketched_;
  Eigen::MatrixXd sketch_;
  Eigen::MatrixXd jacobian_;
};

}  // namespace

KeyframeProjection project_onto_keyframes(Problem& problem, const Scene& scene, const VecX& z,
                                          const ProjectionOptions& options) {
  KeyframeProjection out;
  out.z = z;
  bool all_placed = false;
  std::vector<PlacedKeyframe> placed = placed_keyframes(problem, scene, &all_placed);
  if (placed.empty() || !all_placed || !scene.cloth || problem.size() == 0) return out;
  VecX x0, v0;
  problem.system().initial_state(x0, v0);
  const bool sketch = options.sketch && sketched(placed);
  const long rows = sketch ? residual_sketch(placed, x0, VecX()).rows() + 1 : residual_count(placed);
  if (2 * rows > options.max_passes) return out;
  Projector projector(problem, std::move(placed), cloth_tolerance(scene), options);
  projector.run(z, out);
  return out;
}

KeyframeProjection project_unmet_then_all(Problem& problem, const Scene& scene, const VecX& z,
                                          const std::vector<bool>& unmet, const ProjectionOptions& options) {
  const std::vector<double> scales = problem.weight_scales();
  std::vector<double> pressed(scene.objectives.size(), 1.0);
  for (size_t k = 0; k < pressed.size(); ++k) {
    if (k < scales.size()) pressed[k] = scales[k];
    if (k >= unmet.size() || !unmet[k]) pressed[k] = 0.0;
  }
  ProjectionOptions o = options;
  o.max_passes = options.max_passes / 2;
  problem.set_weight_scales(pressed);
  KeyframeProjection first = project_onto_keyframes(problem, scene, z, o);
  problem.set_weight_scales(scales);
  if (first.stop == ProjectionStop::kNotApplicable || first.stop == ProjectionStop::kDiverged ||
      first.stop == ProjectionStop::kInterrupted || first.stop == ProjectionStop::kFar)
    return first;
  // The met keyframes are at most one tolerance off, so the unmet ones' worst at the start is every keyframe's.
  o.max_passes = options.max_passes - first.simulations - first.adjoint_passes;
  KeyframeProjection all = project_onto_keyframes(problem, scene, first.z, o);
  all.start_worst = first.start_worst;
  all.iterations += first.iterations;
  all.simulations += first.simulations;
  all.adjoint_passes += first.adjoint_passes;
  all.refused += first.refused;
  if (!std::isnan(first.first_gain)) all.first_gain = first.first_gain;
  if (all.stop == ProjectionStop::kNotApplicable || all.stop == ProjectionStop::kDiverged) all.z = z, all.worst = all.start_worst;
  return all;
}

namespace {

const char* stop_name(ProjectionStop s) {
  switch (s) {
    case ProjectionStop::kReached: return "reached";
    case ProjectionStop::kStalled: return "stalled";
    case ProjectionStop::kBudget: return "budget";
    case ProjectionStop::kInterrupted: return "interrupted";
    case ProjectionStop::kNotApplicable: return "not applicable";
    case ProjectionStop::kDiverged: return "start diverged";
    case ProjectionStop::kFar: return "too far to start";
  }
  return "?";
}

}  // namespace

std::string describe(const KeyframeProjection& p) {
  std::ostringstream os;
  os << std::setprecision(3) << "Gauss-Newton onto the keyframes: " << stop_name(p.stop) << " after " << p.iterations
     << " Jacobian" << (p.iterations == 1 ? "" : "s") << " (" << p.simulations << " simulations, " << p.adjoint_passes
     << " adjoint passes, " << p.refused << " trial" << (p.refused == 1 ? "" : "s") << " refused, first step's gain "
     << p.first_gain << "), worst keyframe " << p.start_worst << " -> " << p.worst << " tolerances";
  return os.str();
}

}  // namespace kf

#include "opt/keyframe_projection.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "opt/keyframe_residuals.h"
#include "opt/keyframes/keyframe_common.h"

namespace kf {

namespace {

// The metric steps are smallest in: k(i, j) = 1 + (x_i − c)·(x_j − c) / R² + exp(−‖x_i − x_j‖² / (2σ²)) over the
// sheet's initial positions (c its centroid, R its RMS radius, σ = R / 2). The affine part holds a rigid
// Δv + ω × r, the Gaussian a bend. Minimum-norm in plain velocities, a step moves the keyframed particles
// alone (their own velocities move them most), and the springs then pull them back: the linear model fails.
Eigen::MatrixXd smooth_kernel(const VecX& x0) {
  const long p = x0.size() / 3;
  Vec3 c = Vec3::Zero();
  for (long i = 0; i < p; ++i) c += x0.segment<3>(3 * i);
  c /= double(std::max<long>(1, p));
  double r2 = 0;
  for (long i = 0; i < p; ++i) r2 += (x0.segment<3>(3 * i) - c).squaredNorm();
  r2 = std::max(1e-6, r2 / double(std::max<long>(1, p)));
  const double two_sigma2 = 2 * 0.25 * r2;
  Eigen::MatrixXd k(p, p);
  for (long i = 0; i < p; ++i)
    for (long j = 0; j < p; ++j) {
      const Vec3 a = x0.segment<3>(3 * i) - c, b = x0.segment<3>(3 * j) - c;
      k(i, j) = 1 + a.dot(b) / r2 + std::exp(-(a - b).squaredNorm() / two_sigma2);
    }
  return k;
}

class Projector {
 public:
  Projector(Problem& problem, std::vector<PlacedKeyframe> placed, double tolerance, const ProjectionOptions& o)
      : flight_(problem, std::move(placed)), tolerance_(tolerance), o_(o) {
    jacobian_.resize(flight_.rows(), problem.size());
    VecX x0, v0;
    problem.system().initial_state(x0, v0);
    kernel_ = o.smooth ? smooth_kernel(x0) : Eigen::MatrixXd::Identity(x0.size() / 3, x0.size() / 3);
  }

  void run(VecX z, KeyframeProjection& out) {
    if (!flight_.fly(z)) return finish(out, ProjectionStop::kDiverged);
    VecX r = flight_.residuals();
    double worst = flight_.worst();
    out.z = z;
    out.start_worst = out.worst = worst / tolerance_;
    double cost = 0.5 * r.squaredNorm();
    double mu = -1, nu = 2;
    const double reach = o_.reach_share * tolerance_;
    for (;;) {
      if (worst <= reach) return finish(out, ProjectionStop::kReached);
      // The last flight is z's: a refused trial is always followed by another until one is taken.
      if (!jacobian()) return finish(out, stopped());
      ++out.iterations;
      // In the kernel's metric: the step is −K Jᵀ y, so the linearised residuals change by −J K Jᵀ y.
      const Eigen::MatrixXd jk = times_kernel(jacobian_);
      const Eigen::MatrixXd a = jk * jacobian_.transpose();
      const double scale = std::max(1e-300, a.diagonal().maxCoeff());
      if (mu < 0) mu = 1e-6 * scale;
      for (;;) {
        Eigen::MatrixXd damped = a;
        damped.diagonal().array() += mu;
        const VecX y = damped.ldlt().solve(r);
        VecX dz = -(jk.transpose() * y);
        if (!dz.allFinite()) return finish(out, ProjectionStop::kStalled);
        const double largest = dz.cwiseAbs().maxCoeff();
        const double shrink = largest > o_.max_step ? o_.max_step / largest : 1.0;
        dz *= shrink;
        // The linearised residuals after the step: r − shrink · A y.
        const double predicted = cost - 0.5 * (r - shrink * (a * y)).squaredNorm();
        if (out_of_budget()) return finish(out, stopped());
        const VecX trial_z = z + dz;
        const bool flew = flight_.fly(trial_z);
        const double trial_cost = flew ? 0.5 * flight_.residuals().squaredNorm() : INFINITY;
        if (trial_cost < cost) {
          const double gain = predicted > 0 ? (cost - trial_cost) / predicted : 0;
          mu *= std::max(1.0 / 3, 1 - std::pow(2 * gain - 1, 3));
          nu = 2;
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
        mu *= nu;
        nu *= 2;
        if (largest * shrink < 1e-12 || mu > 1e12 * scale) return finish(out, ProjectionStop::kStalled);
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

  // Each row of j (one number per particle and axis, particle-major) times the kernel, axis by axis.
  Eigen::MatrixXd times_kernel(const Eigen::MatrixXd& j) const {
    const long p = kernel_.rows();
    Eigen::MatrixXd out(j.rows(), j.cols());
    Eigen::MatrixXd axis(j.rows(), p);
    for (int c = 0; c < 3; ++c) {
      for (long i = 0; i < p; ++i) axis.col(i) = j.col(3 * i + c);
      const Eigen::MatrixXd smoothed = axis * kernel_;
      for (long i = 0; i < p; ++i) out.col(3 * i + c) = smoothed.col(i);
    }
    return out;
  }

  // One adjoint pass per residual over the last flight: the rows of dr/dz.
  bool jacobian() {
    VecX unit = VecX::Zero(flight_.rows()), row;
    for (int k = 0; k < flight_.rows(); ++k) {
      if (out_of_budget()) return false;
      unit.setZero();
      unit[k] = 1;
      if (!flight_.transpose_times(unit, row)) return false;
      jacobian_.row(k) = row.transpose();
    }
    return true;
  }

  ResidualFlight flight_;
  double tolerance_;
  ProjectionOptions o_;
  Eigen::MatrixXd jacobian_;
  Eigen::MatrixXd kernel_;
};

}  // namespace

KeyframeProjection project_onto_keyframes(Problem& problem, const Scene& scene, const VecX& z,
                                          const ProjectionOptions& options) {
  KeyframeProjection out;
  out.z = z;
  bool all_placed = false;
  std::vector<PlacedKeyframe> placed = placed_keyframes(problem, scene, &all_placed);
  const Controls& c = problem.controls();
  if (placed.empty() || !all_placed || !scene.cloth || c.kind() != ControlKind::kInitialVelocity ||
      problem.size() != 3 * problem.system().particles() || 2 * residual_count(placed) > options.max_passes)
    return out;
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
      first.stop == ProjectionStop::kInterrupted)
    return first;
  // The met keyframes are at most one tolerance off, so the unmet ones' worst at the start is every keyframe's.
  o.max_passes = options.max_passes - first.simulations - first.adjoint_passes;
  KeyframeProjection all = project_onto_keyframes(problem, scene, first.z, o);
  all.start_worst = first.start_worst;
  all.iterations += first.iterations;
  all.simulations += first.simulations;
  all.adjoint_passes += first.adjoint_passes;
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
  }
  return "?";
}

}  // namespace

std::string describe(const KeyframeProjection& p) {
  std::ostringstream os;
  os << std::setprecision(3) << "Gauss-Newton onto the keyframes: " << stop_name(p.stop) << " after " << p.iterations
     << " Jacobian" << (p.iterations == 1 ? "" : "s") << " (" << p.simulations << " simulations, " << p.adjoint_passes
     << " adjoint passes), worst keyframe " << p.start_worst << " -> " << p.worst << " tolerances";
  return os.str();
}

}  // namespace kf

#include "opt/rigid_throw_fit.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "opt/keyframes/keyframe_common.h"

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

}  // namespace

RigidThrowFit fit_rigid_throw(Problem& problem, const Scene& scene, const std::vector<VecX>& starts,
                              const RigidFitOptions& options) {
  if (problem.controls().kind() != ControlKind::kInitialRigidVelocity)
    throw std::logic_error("fit_rigid_throw: the problem's controls are not a rigid throw");
  RigidThrowFit best;
  FewFitOptions o = options;
  o.scales = VecX::Ones(6);
  o.scales.tail<3>().setConstant(sheet_radius(problem));  // (Δv, ω · radius): rim and centre speeds alike
  FewVariableFit fitter(problem, scene, 6, [](const VecX& y, VecX& z) { z = y; }, o);
  if (fitter.empty()) {
    best.stops.push_back(RigidFitStop::kNoResiduals);
    return best;
  }
  best.cost = INFINITY;
  for (const VecX& start : starts) {
    if (fitter.simulated() >= options.max_simulations || (options.stop && options.stop->load())) break;
    VecX z = start;
    double cost = INFINITY, worst = INFINITY, start_cost = INFINITY;
    const FitStop why = fitter.fit(z, cost, worst, start_cost);
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
  for (size_t k = 0; k < fit.stops.size(); ++k) os << (k ? ", " : "") << fit_stop_name(fit.stops[k]);
  os << "), " << fit.simulated << " flights";
  if (fit.z.size() == 6) os << ", worst keyframe " << fit.worst_miss << " tolerances";
  return os.str();
}

}  // namespace kf

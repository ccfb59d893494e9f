#include "opt/uniform_push.h"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace kf {

VecX uniform_push_controls(Problem& problem, const Vec3& a) {
  const Controls& c = problem.controls();
  if (!c.forces()) return {};
  const VecX& m = problem.system().masses();
  const long per_block = 3 * m.size();
  const long blocks = c.per_particle_forces(c.initial_guess()).size() / std::max(1L, per_block);
  VecX forces(blocks * per_block);
  for (long b = 0; b < blocks; ++b)
    for (long i = 0; i < m.size(); ++i) forces.segment<3>(b * per_block + 3 * i) = m[i] * a;
  return c.remap_from(forces, problem.time(), c.first_frame());
}

FewFitOptions uniform_push_options(const Scene& scene, int flights) {
  FewFitOptions o;
  o.max_simulations = flights;
  o.max_step = 5;            // m/s²: a tilt of gravity by half of it
  o.difference_step = 0.1;   // m/s²: a slope over the contact's kinks, which a millimetre's difference sees
  o.reach_share = 0.25;      // keyframes met with a margin: the stage judges them, not more flights
  o.max_norm = scene.cloth ? 0.5 * scene.cloth->gravity.norm() : 0;  // a push past it is no tilt of gravity
  o.paying_steps = 4;
  o.paying_share = 0.5;
  return o;
}

UniformPush fit_uniform_push(Problem& problem, const Scene& scene, const FewFitOptions& options) {
  if (!problem.controls().forces()) throw std::logic_error("fit_uniform_push: the problem's controls are not forces");
  problem.system().release_step_schedule();
  UniformPush push;
  FewVariableFit fitter(problem, scene, 3, [&problem](const VecX& y, VecX& z) {
    z = uniform_push_controls(problem, Vec3(y));
  }, options);
  if (fitter.empty()) return push;
  VecX y = VecX::Zero(3);
  double cost = INFINITY, worst = INFINITY, start_cost = INFINITY;
  push.stop = fitter.fit(y, cost, worst, start_cost);
  push.simulated = fitter.simulated();
  push.costs = fitter.costs();
  push.start_cost = start_cost;
  if (!std::isfinite(cost)) return push;
  push.a = Vec3(y);
  push.z = uniform_push_controls(problem, push.a);
  push.cost = cost;
  push.worst_miss = worst / fitter.tolerance();
  return push;
}

std::string describe(const UniformPush& push) {
  std::ostringstream os;
  os << std::setprecision(3) << "uniform push: Levenberg-Marquardt " << fit_stop_name(push.stop) << " after "
     << push.simulated << " flights";
  if (push.z.size())
    os << ", a = (" << push.a.x() << ", " << push.a.y() << ", " << push.a.z() << ") m/s^2, keyframes' cost "
       << push.start_cost << " -> " << push.cost << ", worst keyframe " << push.worst_miss << " tolerances";
  if (push.costs.size() > 1) {
    os << " (cost after each step:";
    for (size_t k = 1; k < push.costs.size(); ++k) os << ' ' << push.costs[k] / push.costs[0];
    os << " of the start's)";
  }
  return os.str();
}

}  // namespace kf

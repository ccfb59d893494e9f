#include "opt/budget_extension.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace kf {

BudgetExtension plan_budget_extension(const BudgetExtensionRule& rule, const BudgetExtensionFacts& f) {
  BudgetExtension e;
  if (f.stated || !f.budget_stop || f.met) return e;
  e.considered = true;
  std::ostringstream os;
  os.precision(3);
  if (!(f.worst_miss <= rule.near_limit)) {
    os << "default budget not extended: the worst keyframe is " << f.worst_miss << " tolerances off, over "
       << rule.near_limit;
    e.why = os.str();
    return e;
  }
  if (f.expected <= 0) {
    e.why = "default budget not extended: the last stage's objective no longer fell over its last tenth";
    return e;
  }
  const int by_share = int(std::floor(rule.max_share * f.budget));
  const int by_cost = f.particle_steps > 0 ? int(std::floor(rule.max_particle_steps / f.particle_steps)) : by_share;
  const int allowed = std::min(by_share, by_cost);
  if (f.expected > allowed) {
    os << "default budget not extended: at the last stage's rate the worst keyframe (" << f.worst_miss
       << " tolerances off) needs about " << f.expected << " more evaluations, over the " << allowed
       << " an extension may take (" << (by_cost < by_share ? "its cost in particle-steps" : "a share of the budget")
       << ")";
    e.why = os.str();
    return e;
  }
  e.evaluations = std::min(allowed, std::max(rule.min_evaluations, int(std::ceil(f.expected * rule.margin))));
  os << "default budget of " << f.budget << " extended by " << e.evaluations << " evaluations: the worst keyframe is "
     << f.worst_miss << " tolerances off and at the last stage's rate needs about " << f.expected << " more";
  e.why = os.str();
  return e;
}

double recent_improvement(const std::vector<double>& phis) {
  if (phis.size() < 2) return 1.0;
  const size_t earlier = phis.size() - std::max<size_t>(1, phis.size() / 10);
  double best = INFINITY, best_earlier = INFINITY;
  for (size_t i = 0; i < phis.size(); ++i) {
    if (!std::isfinite(phis[i])) continue;
    best = std::min(best, phis[i]);
    if (i < earlier) best_earlier = std::min(best_earlier, phis[i]);
  }
  return std::isfinite(best_earlier) && best_earlier > 0 ? best / best_earlier : 1.0;
}

}  // namespace kf

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
  os << "default budget not extended: ";
  const int by_share = int(std::floor(rule.max_share * f.budget));
  const int by_cost = f.particle_steps > 0 ? int(std::floor(rule.max_particle_steps / f.particle_steps)) : by_share;
  const int allowed = std::min(by_share, by_cost);
  if (!(f.worst_miss <= rule.near_limit)) {
    os << "the worst keyframe is " << f.worst_miss << " tolerances off, over " << rule.near_limit;
  } else if (!(f.effort_share >= rule.min_effort_share)) {
    os << "the effort is " << std::lround(100 * f.effort_share) << " % of the objective, below "
       << std::lround(100 * rule.min_effort_share) << " %: it is not what holds the keyframe back";
  } else if (allowed < rule.min_evaluations) {
    os << "its cost in particle-steps allows " << allowed << " evaluations, fewer than " << rule.min_evaluations;
  } else {
    e.evaluations = allowed;
    os.str("");
    os << "default budget of " << f.budget << " extended by " << allowed << " evaluations with the unmet keyframes' "
       << "weights raised: the worst keyframe is " << f.worst_miss << " tolerances off and the effort "
       << std::lround(100 * f.effort_share) << " % of the objective";
  }
  e.why = os.str();
  return e;
}

}  // namespace kf

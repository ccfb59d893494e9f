#include "opt/uncontrolled_floor.h"

#include <cmath>
#include <iomanip>
#include <sstream>

namespace kf {

namespace {

struct Judged {
  bool ok = false;  // simulated to the end with finite keyframe terms
  std::vector<double> terms;
  std::vector<bool> unmet;
  int met = 0;
  double sum = 0;
};

Judged judge(Problem& problem, const VecX& z, const std::function<std::vector<bool>(Problem&)>& unmet) {
  Judged j;
  problem.evaluate(z, nullptr);
  if (problem.last_diverged()) return j;
  const auto& breakdown = problem.breakdown();
  for (size_t k = 0; k + 1 < breakdown.size(); ++k) j.terms.push_back(breakdown[k].second);  // the last is effort
  j.unmet = unmet(problem);
  j.ok = true;
  for (size_t k = 0; k < j.terms.size(); ++k) {
    j.ok = j.ok && std::isfinite(j.terms[k]);
    j.sum += j.terms[k];
    j.met += k < j.unmet.size() && !j.unmet[k];
  }
  return j;
}

// The first keyframe j leaves unmet farther off than `none` does, or -1.
int worse_than(const Judged& j, const Judged& none) {
  for (size_t k = 0; k < j.terms.size() && k < none.terms.size(); ++k)
    if (k < j.unmet.size() && j.unmet[k] && j.terms[k] > none.terms[k]) return int(k);
  return -1;
}

}  // namespace

FloorVerdict uncontrolled_floor(Problem& problem, const std::vector<VecX>& candidates,
                                const std::function<std::vector<bool>(Problem&)>& unmet,
                                const std::function<void(size_t)>& before) {
  FloorVerdict v;
  if (candidates.empty()) return v;
  const auto prepare = [&](size_t c) {
    if (before) before(c);
  };
  const VecX none_z = problem.initial_guess();
  prepare(candidates.size());
  const Judged none = judge(problem, none_z, unmet);
  prepare(0);
  const Judged result = judge(problem, candidates[0], unmet);
  const int worse = none.ok ? worse_than(result, none) : -1;
  if (!none.ok || (result.ok && worse < 0)) return v;  // left evaluated at the result
  size_t best = candidates.size();
  Judged best_j = none;
  for (size_t c = 1; c < candidates.size(); ++c) {
    if (candidates[c].size() != none_z.size()) continue;
    prepare(c);
    const Judged j = judge(problem, candidates[c], unmet);
    if (!j.ok || worse_than(j, none) >= 0) continue;
    if (j.met > best_j.met || (j.met == best_j.met && j.sum < best_j.sum)) {
      best = c;
      best_j = j;
    }
  }
  v.chosen = best;
  std::ostringstream os;
  os << std::scientific << std::setprecision(3);
  if (worse >= 0)
    os << "the result leaves " << problem.breakdown()[size_t(worse)].first << " farther off than uncontrolled";
  else
    os << "the result diverges";
  os << ": the run ends at ";
  if (best == candidates.size()) os << "no control";
  else os << "the end of an earlier stage (keyframe terms " << best_j.sum << ", " << best_j.met << " met)";
  v.why = os.str();
  prepare(best);
  problem.evaluate(best == candidates.size() ? none_z : candidates[best], nullptr);
  return v;
}

}  // namespace kf

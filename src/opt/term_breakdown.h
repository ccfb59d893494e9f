#pragma once
// Problem::breakdown()'s entries by role, told apart by where Problem::evaluate puts them, not by a term's
// name: after a rollout that did not diverge, the keyframe terms (scene.objectives order) and then the
// control effort; after one that diverged, a single entry and no effort.
#include <cstddef>
#include <optional>

#include "opt/problem.h"

namespace kf {

// The control effort of the problem's last evaluation, as φ summed it; none after a divergence or before
// any evaluation.
inline std::optional<double> last_effort(const Problem& problem) {
  const auto& terms = problem.breakdown();
  if (problem.last_diverged() || terms.empty()) return std::nullopt;
  return terms.back().second;
}

// The sum of the last evaluation's entries but its effort (the keyframe terms, weighted as φ sums them).
inline double keyframe_terms_sum(const Problem& problem) {
  const auto& terms = problem.breakdown();
  const std::size_t n = last_effort(problem) ? terms.size() - 1 : terms.size();
  double sum = 0;
  for (std::size_t k = 0; k < n; ++k) sum += terms[k].second;
  return sum;
}

}  // namespace kf

#pragma once
// What the whole-simulation gradient tests share: the end-target cost and keyframe gradcheck's check at
// zero and perturbed controls.
#include <functional>
#include <random>

#include "adjoint/rollout.h"
#include "opt/gradcheck.h"
#include "opt/problem.h"

namespace kf::test {

// phi = |x_last - target|^2 / 2 at step `last` (target: 3p, metres).
struct EndTarget : StateCost {
  int last = 0;
  VecX target;
  bool active(int n) const override { return n == last; }
  double eval(int, const VecX& x, const VecX&, VecX& gx, VecX&) const override {
    gx += x - target;
    return 0.5 * (x - target).squaredNorm();
  }
};

// gradcheck (16 samples, seed 5, step eps) at the problem's initial controls moved by seeded normal noise
// of each size in `perturbs` (0: the controls themselves); `report` gets each size and its result.
inline void gradcheck_perturbed(Problem& problem, double eps, std::initializer_list<double> perturbs,
                                const std::function<void(double, const GradcheckResult&)>& report) {
  for (double perturb : perturbs) {
    VecX z = problem.initial_guess();
    std::mt19937_64 rng(3);
    std::normal_distribution<double> normal(0.0, perturb);
    for (int i = 0; i < z.size(); ++i) z[i] += normal(rng);
    report(perturb, gradcheck(problem, z, {.samples = 16, .eps = eps, .seed = 5}));
  }
}

}  // namespace kf::test

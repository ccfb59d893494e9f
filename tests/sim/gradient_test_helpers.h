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

// The problem's initial controls moved by seeded normal noise of standard deviation `sigma` (control units).
inline VecX perturbed_controls(Problem& problem, double sigma, std::uint64_t seed) {
  VecX z = problem.initial_guess();
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, sigma);
  for (int i = 0; i < z.size(); ++i) z[i] += normal(rng);
  return z;
}

// gradcheck (16 samples, seed 5, step eps) at the problem's initial controls moved by seeded normal noise
// of each size in `perturbs` (0: the controls themselves); `report` gets each size and its result.
inline void gradcheck_perturbed(Problem& problem, double eps, std::initializer_list<double> perturbs,
                                const std::function<void(double, const GradcheckResult&)>& report) {
  for (double perturb : perturbs) {
    const VecX z = perturbed_controls(problem, perturb, 3);
    report(perturb, gradcheck(problem, z, {.samples = 16, .eps = eps, .seed = 5}));
  }
}

}  // namespace kf::test

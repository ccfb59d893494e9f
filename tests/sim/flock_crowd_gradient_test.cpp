// The flock gradient at crowd scale: 10,000 agents packed at the spawn's densest, random controls,
// sampled against central finite differences at two step sizes (Release builds only: a Debug build runs
// the ~40 rollouts too slowly).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "adjoint/rollout.h"
#include "sim/flock/flock_system.h"
#include "sim/flock/neighbor_grid.h"
#include "random_flock.h"

namespace kf {
namespace {

// phi = 1/2 sum over the watched agents of |x_N,i - target_i|^2: a few agents, so phi is O(1) and its
// finite differences are not lost in the round-off of a sum over 10,000 agents.
class WatchedAgentsCost final : public StateCost {
 public:
  WatchedAgentsCost(int N, std::vector<int> agents, VecX target)
      : N_(N), agents_(std::move(agents)), target_(std::move(target)) {}
  bool active(int n) const override { return n == N_; }
  double eval(int, const VecX& x, const VecX&, VecX& gx, VecX&) const override {
    double phi = 0;
    for (int i : agents_) {
      const Vec3 d = seg(x, i) - seg(target_, i);
      seg(gx, i) += d;
      phi += 0.5 * d.squaredNorm();
    }
    return phi;
  }

 private:
  int N_;
  std::vector<int> agents_;
  VecX target_;
};

void check_crowd_gradient(bool implicit_damping) {
  const int p = 10000, N = 6;
  FlockSpec spec;
  spec.agents = p;
  spec.implicit_damping = implicit_damping;
  // 1 agent per m^2, as densely as the spawn lattice's 0.9 m spacing allows: ~28 neighbours each. (At 2 per
  // m^2 the lattice holds only half of them, and the rest all start at the centre.)
  spec.spawn.radius = std::sqrt(p / M_PI);
  spec.spawn.velocity = Vec3(0.8, 0, 0.2);
  spec.wander.correlation_steps = 10;
  FlockSystem sys(spec, 1.0 / 30, N, 11);
  std::mt19937_64 rng(35);
  VecX x0, v0;
  sys.initial_state(x0, v0);
  std::vector<VecX> U(N);
  for (auto& u : U) u = random_planar(p, 0.5, rng);
  Rollout r;
  ASSERT_TRUE(simulate(sys, x0, v0, U, r)) << sys.divergence_reason();

  std::vector<int> watched;
  for (int i = 0; i < p; i += 500) watched.push_back(i);  // 20 agents spread over the crowd
  const WatchedAgentsCost cost(N, watched, r.x[N] + random_planar(p, 0.3, rng));
  std::vector<VecX> dU;
  VecX dx0, dv0;
  backward(sys, r, U, cost, dU, dx0, dv0);

  // Samples: a watched agent's own control at the first, a middle and the last step, and controls of its
  // neighbours at the first step (they reach it only through the pair forces).
  NeighborGrid grid;
  grid.build(x0, spec.matching.radius);
  struct Sample {
    int n, k;
  };
  std::vector<Sample> samples;
  for (int w = 0; w < 2; ++w) {
    const int i = watched[w];
    samples.push_back({w % 2 ? N / 2 : 0, 3 * i});
    samples.push_back({N - 1, 3 * i + 2});
    const auto nb = grid.neighbors(i);
    ASSERT_GE(nb.size(), 10u) << "the crowd must be bunched";
    samples.push_back({0, 3 * nb[nb.size() / 2] + 2 * (w % 2)});
  }
  auto phi = [&](const std::vector<VecX>& UU) {
    Rollout rr;
    EXPECT_TRUE(simulate(sys, x0, v0, UU, rr));
    return cost_value(cost, rr);
  };
  auto central = [&](const Sample& s, double eps) {
    std::vector<VecX> Up = U, Um = U;
    Up[s.n][s.k] += eps;
    Um[s.n][s.k] -= eps;
    return (phi(Up) - phi(Um)) / (2 * eps);
  };
  ASSERT_GT(cost_value(cost, r), 0.1);
  // Central differences at h and 2h; the reference is their Richardson extrapolation (error O(h^4)). phi's
  // round-off is ~1e-12 here (it sums over 10,000 agents' motion), so smaller steps are noisier, not better:
  // at 1e-6 and 1e-5 the differences of a neighbour's control scattered by 4e-7 and 6e-8.
  const double h = 1e-4;
  double largest = 0, worst = 0, spread = 0, smallest_neighbour = 1e300;
  std::vector<double> fd(samples.size());
  for (size_t s = 0; s < samples.size(); ++s) {
    const double fine = central(samples[s], h), coarse = central(samples[s], 2 * h);
    fd[s] = (4 * fine - coarse) / 3;
    spread = std::max(spread, std::abs(fine - coarse));
    largest = std::max(largest, std::abs(fd[s]));
    if (s % 3 == 2) smallest_neighbour = std::min(smallest_neighbour, std::abs(fd[s]));
  }
  for (size_t s = 0; s < samples.size(); ++s) {
    const double a = dU[samples[s].n][samples[s].k];
    const double err = std::abs(a - fd[s]) / std::max(std::abs(fd[s]), 1e-3 * largest);
    std::printf("  u_%d[%d]: adjoint %.12g, finite differences %.12g, relative error %.2g\n", samples[s].n,
                samples[s].k, a, fd[s], err);
    worst = std::max(worst, err);
  }
  std::printf("crowd gradient: %zu samples, largest |fd| %.3g, smallest neighbour |fd| %.3g, step-size spread %.2g, "
              "worst relative error %.2g\n",
              samples.size(), largest, smallest_neighbour, spread, worst);
  ASSERT_GT(largest, 1e-4);  // far above phi's round-off (~1e-12 / 1e-4 in a difference quotient)
  ASSERT_GT(smallest_neighbour, 1e-9) << "a neighbour's control must reach the watched agent";
  // h and 2h differ by their O(h^2) truncation (4e-6 of the largest when this was written), which the
  // extrapolation removes; a kink or round-off would show as a larger disagreement.
  ASSERT_LT(spread, 1e-5 * largest) << "the two step sizes disagree: the differences are not trustworthy";
  EXPECT_LT(worst, 1e-6);
}

TEST(FlockCrowd, GradientAtTenThousandAgentsMatchesSampledFiniteDifferences) {
#ifndef NDEBUG
  GTEST_SKIP() << "10,000 agents: Release builds only";
#endif
  check_crowd_gradient(false);
}

// The crowd sweep's step: damping taken implicitly.
TEST(FlockCrowd, ImplicitDampingGradientAtTenThousandAgentsMatchesSampledFiniteDifferences) {
#ifndef NDEBUG
  GTEST_SKIP() << "10,000 agents: Release builds only";
#endif
  check_crowd_gradient(true);
}

}  // namespace
}  // namespace kf

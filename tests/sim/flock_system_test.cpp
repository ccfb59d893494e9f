// The flock step, its adjoint and the full gradient through a rollout, against finite differences.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstdio>
#include <limits>
#include <random>

#include "adjoint/rollout.h"
#include "sim/flock/flock_system.h"
#include "random_flock.h"

namespace kf {
namespace {

// 20 agents ~1 m apart with every force on (defaults) and a little initial motion.
FlockSpec small_flock(int agents = 20) {
  FlockSpec s;
  s.agents = agents;
  s.spawn.radius = std::sqrt(agents / M_PI) * 1.1;
  s.spawn.velocity = Vec3(0.8, 0, 0.2);
  s.wander.correlation_steps = 10;
  return s;
}

// Largest |a - fd| relative to max(|fd|, floor x the largest fd entry).
double max_relative_error(const VecX& a, const VecX& fd, double floor_fraction) {
  const double floor = floor_fraction * fd.cwiseAbs().maxCoeff();
  double worst = 0;
  for (int k = 0; k < fd.size(); ++k) worst = std::max(worst, std::abs(a[k] - fd[k]) / std::max(std::abs(fd[k]), floor));
  return worst;
}

TEST(FlockSystem, StepIsPlanarAndMovesTheFlock) {
  FlockSystem sys(small_flock(), 1.0 / 30, 100, 4);
  VecX x, v, x1, v1;
  sys.initial_state(x, v);
  ASSERT_EQ(x.size(), 60);
  VecX u = VecX::Constant(60, 0.3);  // y part of a control is ignored
  for (int n = 0; n < 100; ++n) {
    ASSERT_TRUE(sys.step(n, x, v, u, x1, v1));
    for (int i = 0; i < 20; ++i) ASSERT_TRUE(x1[3 * i + 1] == 0.0 && v1[3 * i + 1] == 0.0);
    x.swap(x1);
    v.swap(v1);
  }
  // Centering keeps the group together; avoidance keeps agents apart.
  double closest = 1e9, farthest = 0;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < i; ++j) {
      closest = std::min(closest, (seg(x, i) - seg(x, j)).norm());
      farthest = std::max(farthest, (seg(x, i) - seg(x, j)).norm());
    }
  EXPECT_GT(closest, 0.3);
  EXPECT_LT(farthest, 12.0);
}

TEST(FlockSystem, StepReportsNonFiniteResults) {
  FlockSystem sys(small_flock(), 1.0 / 30, 10, 4);
  VecX x, v, x1, v1;
  sys.initial_state(x, v);
  VecX u = VecX::Zero(60);
  u[3] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(sys.step(0, x, v, u, x1, v1));
  u[3] = 0;
  u[0] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(sys.step(0, x, v, u, x1, v1));
}

// One step's adjoint against central differences of J = a . x1 + b . v1 at a random state with a coincident
// pair, for every entry of xhat, vhat and uhat.
void check_one_step_adjoint(const FlockSpec& spec) {
  const int p = spec.agents;
  FlockSystem sys(spec, 1.0 / 30, 10, 4);
  std::mt19937_64 rng(3);
  VecX x, v;
  sys.initial_state(x, v);
  x += random_planar(p, 0.3, rng);
  seg(x, 1) = seg(x, 0);  // a coincident pair
  v = random_planar(p, 1.0, rng);
  const VecX u = random_planar(p, 0.5, rng);
  // J = a . x1 + b . v1 (the y parts of a and b must not leak anywhere).
  const VecX a = random_planar(p, 1.0, rng) + VecX::Constant(3 * p, 0.7), b = random_planar(p, 1.0, rng);
  VecX xhat, vhat, uhat;
  sys.step_adjoint(3, x, v, u, a, b, xhat, vhat, uhat);
  for (int i = 0; i < p; ++i) ASSERT_TRUE(xhat[3 * i + 1] == 0 && vhat[3 * i + 1] == 0 && uhat[3 * i + 1] == 0);

  auto J = [&](const VecX& xx, const VecX& vv, const VecX& uu) {
    VecX x1, v1;
    EXPECT_TRUE(sys.step(3, xx, vv, uu, x1, v1));
    return a.dot(x1) + b.dot(v1);
  };
  const double eps = 1e-5;
  VecX fx = VecX::Zero(3 * p), fv = fx, fu = fx;
  for (int k = 0; k < 3 * p; ++k) {
    if (k % 3 == 1) continue;
    VecX e = VecX::Zero(3 * p);
    e[k] = eps;
    fx[k] = (J(x + e, v, u) - J(x - e, v, u)) / (2 * eps);
    fv[k] = (J(x, v + e, u) - J(x, v - e, u)) / (2 * eps);
    fu[k] = (J(x, v, u + e) - J(x, v, u - e)) / (2 * eps);
  }
  ASSERT_GT(fx.norm(), 0.0);
  ASSERT_GT(fv.norm(), 0.0);
  ASSERT_GT(fu.norm(), 0.0);
  EXPECT_LT(max_relative_error(xhat, fx, 1e-6), 1e-6) << "xhat " << xhat.transpose() << "\nfd   " << fx.transpose();
  EXPECT_LT(max_relative_error(vhat, fv, 1e-6), 1e-6) << "vhat " << vhat.transpose() << "\nfd   " << fv.transpose();
  EXPECT_LT(max_relative_error(uhat, fu, 1e-6), 1e-6);
}

TEST(FlockSystem, StepAdjointMatchesFiniteDifferencesOfOneStep) { check_one_step_adjoint(small_flock(20)); }

// Matching strong enough that the damping factor a_i = h (c S_i + drag)/m_i passes 1 for most agents, so
// the implicit step's division by 1 + a_i and its dependence on positions through S_i both weigh.
FlockSpec strongly_damped_flock(int agents) {
  FlockSpec s = small_flock(agents);
  s.matching.strength = 60;
  s.implicit_damping = true;
  return s;
}

TEST(FlockSystem, ImplicitDampingStepAdjointMatchesFiniteDifferencesOfOneStep) {
  check_one_step_adjoint(strongly_damped_flock(20));
}

// phi = 1/2 |x_N - target|^2 + 1/4 |v_N|^2 + 1/2 |x_30 - mid|^2 (a mid-way keyframe).
class TestCost final : public StateCost {
 public:
  TestCost(int N, VecX target, VecX mid) : N_(N), target_(std::move(target)), mid_(std::move(mid)) {}
  bool active(int n) const override { return n == N_ || n == 30; }
  double eval(int n, const VecX& x, const VecX& v, VecX& gx, VecX& gv) const override {
    if (n == 30) {
      gx += x - mid_;
      return 0.5 * (x - mid_).squaredNorm();
    }
    gx += x - target_;
    gv += 0.5 * v;
    return 0.5 * (x - target_).squaredNorm() + 0.25 * v.squaredNorm();
  }

 private:
  int N_;
  VecX target_, mid_;
};

// The gradient of a mid-way and an end keyframe through a 60-step rollout under random controls, entry by
// entry at the start, around the keyframe and at the end, and along random directions, against central
// differences.
void check_rollout_gradient(const FlockSpec& spec) {
  const int p = spec.agents, N = 60;
  FlockSystem sys(spec, 1.0 / 30, N, 8);
  std::mt19937_64 rng(21);
  VecX x0, v0;
  sys.initial_state(x0, v0);
  std::vector<VecX> U(N);
  for (auto& u : U) u = random_planar(p, 0.5, rng);
  // Targets a little away from where the flock goes, so phi is O(1) and its gradient is not tiny.
  Rollout r;
  ASSERT_TRUE(simulate(sys, x0, v0, U, r));
  const TestCost cost(N, r.x[N] + random_planar(p, 0.3, rng), r.x[30] + random_planar(p, 0.3, rng));

  std::vector<VecX> dU;
  VecX dx0, dv0;
  backward(sys, r, U, cost, dU, dx0, dv0);

  auto phi = [&](const VecX& x, const VecX& v, const std::vector<VecX>& UU) {
    Rollout rr;
    EXPECT_TRUE(simulate(sys, x, v, UU, rr));
    return cost_value(cost, rr);
  };
  const double phi0 = phi(x0, v0, U);
  ASSERT_GT(phi0, 0.1);
  const double eps = 1e-5;
  // Every entry of dphi/du_n on steps at the start, around the mid keyframe and at the end, and of
  // dphi/dx0, dphi/dv0 (slots N and N+1); stacked with the finite differences the same way.
  const std::vector<int> slots = {0, 1, 2, 29, 30, 31, 57, 58, 59, N, N + 1};
  VecX analytic(3 * p * int(slots.size())), fd = VecX::Zero(analytic.size());
  for (size_t s = 0; s < slots.size(); ++s) {
    const int n = slots[s];
    analytic.segment(3 * p * s, 3 * p) = n < N ? dU[n] : n == N ? dx0 : dv0;
    for (int k = 0; k < 3 * p; ++k) {
      if (k % 3 == 1) {
        ASSERT_EQ(analytic[3 * p * s + k], 0.0);
        continue;
      }
      std::vector<VecX> Up = U, Um = U;
      VecX xp = x0, xm = x0, vp = v0, vm = v0;
      if (n < N) {
        Up[n][k] += eps;
        Um[n][k] -= eps;
      } else if (n == N) {
        xp[k] += eps;
        xm[k] -= eps;
      } else {
        vp[k] += eps;
        vm[k] -= eps;
      }
      fd[3 * p * s + k] = (phi(xp, vp, Up) - phi(xm, vm, Um)) / (2 * eps);
    }
  }
  ASSERT_GT(fd.cwiseAbs().maxCoeff(), 1e-3);
  const double rel_inf = (analytic - fd).cwiseAbs().maxCoeff() / fd.cwiseAbs().maxCoeff();
  const double rel_floor = max_relative_error(analytic, fd, 1e-3);
  // Every other step through random directions over all controls at once: g . delta vs d phi along delta.
  double rel_dir = 0;
  for (int trial = 0; trial < 12; ++trial) {
    std::vector<VecX> Up = U, Um = U;
    double g_delta = 0;
    for (int n = 0; n < N; ++n) {
      const VecX delta = random_planar(p, 1.0, rng);
      Up[n] += eps * delta;
      Um[n] -= eps * delta;
      g_delta += dU[n].dot(delta);
    }
    const double fd_delta = (phi(x0, v0, Up) - phi(x0, v0, Um)) / (2 * eps);
    ASSERT_GT(std::abs(fd_delta), 1e-3);
    rel_dir = std::max(rel_dir, std::abs(g_delta - fd_delta) / std::abs(fd_delta));
  }
  ::testing::Test::RecordProperty("relative_error_inf_norm", std::to_string(rel_inf));
  ::testing::Test::RecordProperty("relative_error_per_entry_floor_1e-3", std::to_string(rel_floor));
  std::printf("rollout gradient: phi %.6g, max |grad| %.3g, max|a-fd|/max|fd| %.3g, per-entry (floor 1e-3 max) %.3g, "
              "directional %.3g\n",
              phi0, fd.cwiseAbs().maxCoeff(), rel_inf, rel_floor, rel_dir);
  EXPECT_LT(rel_inf, 1e-6);
  EXPECT_LT(rel_floor, 1e-6);
  EXPECT_LT(rel_dir, 1e-6);
}

TEST(FlockSystem, RolloutGradientMatchesFiniteDifferences) { check_rollout_gradient(small_flock(20)); }

TEST(FlockSystem, ImplicitDampingRolloutGradientMatchesFiniteDifferences) {
  check_rollout_gradient(strongly_damped_flock(20));
}

TEST(FlockSystem, BitIdenticalForOneAndTwoThreads) {
  const int p = 800, N = 15;
  auto run = [&](int threads, Rollout& r, std::vector<VecX>& dU) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    FlockSpec spec = small_flock(p);
    FlockSystem sys(spec, 1.0 / 30, N, 5);
    VecX x0, v0;
    sys.initial_state(x0, v0);
    std::mt19937_64 rng(2);
    std::vector<VecX> U(N);
    for (auto& u : U) u = random_planar(p, 1.0, rng);
    ASSERT_TRUE(simulate(sys, x0, v0, U, r));
    const TestCost cost(N, VecX::Zero(3 * p), VecX::Zero(3 * p));
    VecX dx0, dv0;
    backward(sys, r, U, cost, dU, dx0, dv0);
  };
  Rollout r1, r2;
  std::vector<VecX> d1, d2;
  run(1, r1, d1);
  run(2, r2, d2);
  for (int n = 0; n <= N; ++n) {
    ASSERT_TRUE(r1.x[n] == r2.x[n]) << "positions differ at step " << n;
    ASSERT_TRUE(r1.v[n] == r2.v[n]) << "velocities differ at step " << n;
  }
  for (int n = 0; n < N; ++n) ASSERT_TRUE(d1[n] == d2[n]) << "gradient differs at step " << n;
}

}  // namespace
}  // namespace kf

// The cloth adjoints (design §4) against central finite differences of the full simulation.
//
// Controls: a constant force on every particle over the whole run (its gradient is the sum of dphi/du_n)
// and the initial velocities. Cost: ½‖x_N − target‖². The exact adjoint agrees to the differences' own
// accuracy at every step; the integrator-swapping one to what that approximation promises (cosine ≥ 0.99
// at h = 1/60), improving as h falls.
// To stay fast the vectors compared are the force and initial-velocity components of a fixed
// third of the particles (72 of 216 parameters); the full comparison gives the same trend.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "adjoint/rollout.h"
#include "scene/scene.h"
#include "sim/cloth/cloth_system.h"
#include "sim/make_system.h"
#include "gradient_test_helpers.h"

namespace kf {
namespace {

constexpr double kDuration = 40.0 / 60.0;  // seconds, the same for every step size

using test::EndTarget;

struct Study {
  double cosine, relative_error;
};

// `cloth_keys`: more keys of the cloth block (", ..." or empty).
Study study(double h, AdjointKind adjoint, const std::string& cloth_keys = "") {
  const Scene scene = parse_scene(R"({"time": {"fps": 60, "frames": 40},
      "cloth": {"nx": 6, "ny": 6, "width": 0.5, "height": 0.5, "mass": 0.1, "pins": "top_corners",
                "stretch": 200, "shear": 20, "bend": 2, "damping": 0.02, "air_drag": 0.2,
                "velocity": [0, 0, 0.4], "cg_tolerance": 1e-12, "cg_max_iterations": 5000)" + cloth_keys + "}}",
                                  "gradient.json");
  auto sys = make_system(scene, h);
  dynamic_cast<ClothSystem&>(*sys).set_adjoint(adjoint);
  const int N = int(std::lround(kDuration / h)), dof = sys->dof();
  VecX x0, v0;
  sys->initial_state(x0, v0);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> U(-1, 1);
  VecX force(dof);
  for (int k = 0; k < dof; ++k) force[k] = 0.01 * U(rng);
  EndTarget cost;
  cost.last = N;
  cost.target = x0 + VecX::Constant(dof, 0.05);

  auto phi = [&](const VecX& f, const VecX& v) {
    Rollout r;
    EXPECT_TRUE(simulate(*sys, x0, v, std::vector<VecX>(N, f), r));
    return cost_value(cost, r);
  };
  // Adjoint gradient.
  Rollout r;
  const std::vector<VecX> Us(N, force);
  EXPECT_TRUE(simulate(*sys, x0, v0, Us, r));
  std::vector<VecX> dU;
  VecX dx0, dv0;
  backward(*sys, r, Us, cost, dU, dx0, dv0);
  VecX g(2 * dof), fd(2 * dof);
  g.head(dof).setZero();
  for (const VecX& d : dU) g.head(dof) += d;
  g.tail(dof) = dv0;
  // Central differences on the sampled components.
  std::vector<int> sample;
  for (int i = 0; i < sys->particles(); ++i)
    if (i % 3 == 1)
      for (int c = 0; c < 3; ++c) sample.push_back(3 * i + c);
  const double eps_f = 1e-6, eps_v = 1e-5;
  VecX gs(2 * sample.size()), fds(2 * sample.size());
  for (size_t j = 0; j < sample.size(); ++j) {
    const int k = sample[j];
    VecX fp = force, fm = force;
    fp[k] += eps_f;
    fm[k] -= eps_f;
    fd[k] = (phi(fp, v0) - phi(fm, v0)) / (2 * eps_f);
    VecX vp = v0, vm = v0;
    vp[k] += eps_v;
    vm[k] -= eps_v;
    fd[dof + k] = (phi(force, vp) - phi(force, vm)) / (2 * eps_v);
    gs[2 * j] = g[k];
    gs[2 * j + 1] = g[dof + k];
    fds[2 * j] = fd[k];
    fds[2 * j + 1] = fd[dof + k];
  }
  EXPECT_GT(fds.norm(), 0);
  EXPECT_GT(gs.norm(), 0);
  return {gs.dot(fds) / (gs.norm() * fds.norm()), (gs - fds).norm() / fds.norm()};
}

TEST(ClothGradient, ExactAdjointMatchesFiniteDifferencesAndSwapImprovesAsStepFalls) {
  const double hs[] = {1.0 / 30, 1.0 / 45, 1.0 / 60, 1.0 / 120};
  std::vector<Study> exact, swap;
  std::printf("  h        steps  exact rel. error  swap cosine  swap rel. error\n");
  for (double h : hs) {
    exact.push_back(study(h, AdjointKind::kExact));
    swap.push_back(study(h, AdjointKind::kSwap));
    std::printf("  1/%-5.0f  %5ld  %.3e         %.6f     %.3e\n", 1 / h, std::lround(kDuration / h),
                exact.back().relative_error, swap.back().cosine, swap.back().relative_error);
  }
  for (size_t i = 0; i < exact.size(); ++i) EXPECT_LT(exact[i].relative_error, 1e-6) << "h = " << hs[i];
  EXPECT_GE(swap[2].cosine, 0.99);  // h = 1/60
  for (size_t i = 1; i < swap.size(); ++i) {
    EXPECT_GT(swap[i].cosine, swap[i - 1].cosine) << "h = " << hs[i];
    EXPECT_LT(swap[i].relative_error, swap[i - 1].relative_error) << "h = " << hs[i];
  }
}

// The same with a narrow transverse ramp (the scene's transverse_ramp): the exact adjoint's derivative of the
// step's matrix follows the spring's own ramp.
TEST(ClothGradient, ExactAdjointMatchesFiniteDifferencesWithANarrowTransverseRamp) {
  for (double h : {1.0 / 30, 1.0 / 60}) {
    const Study s = study(h, AdjointKind::kExact, R"(, "transverse_ramp": 0.002)");
    std::printf("  h = 1/%.0f, transverse_ramp 0.002: exact rel. error %.3e\n", 1 / h, s.relative_error);
    EXPECT_LT(s.relative_error, 1e-6) << "h = " << h;
  }
}

// The theta step (cloth.theta) below backward Euler's 1: its solve runs with step theta h and its velocity
// keeps part of the last one, which the adjoint's right-hand side and velocity terms follow.
TEST(ClothGradient, ExactAdjointMatchesFiniteDifferencesWithTheThetaStep) {
  for (double theta : {0.5, 0.6})
    for (double h : {1.0 / 30, 1.0 / 60}) {
      const Study s = study(h, AdjointKind::kExact, R"(, "transverse_ramp": 0.002, "theta": )" + std::to_string(theta));
      std::printf("  h = 1/%.0f, theta %.1f: exact rel. error %.3e\n", 1 / h, theta, s.relative_error);
      EXPECT_LT(s.relative_error, 1e-6) << "h = " << h << " theta " << theta;
    }
}

}  // namespace
}  // namespace kf

// Temporary measuring tool: phi(z0 + s d) along the diagnosis probe's direction, and the first step whose
// state departs from linear response. Run with --gtest_also_run_disabled_tests and KF_PROBE_SCENE=file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/make_system.h"

namespace kf {
namespace {

TEST(LineProbeTool, DISABLED_Measure) {
  const char* file = std::getenv("KF_PROBE_SCENE");
  ASSERT_NE(file, nullptr);
  const bool hold = std::getenv("KF_PROBE_HOLD") && std::atoi(std::getenv("KF_PROBE_HOLD"));
  Scene scene = load_scene(file);
  auto env = [](const char* k, double d) { return std::getenv(k) ? std::atof(std::getenv(k)) : d; };
  for (auto& c : scene.cloth->colliders) {
    c.friction *= env("KF_PROBE_MU", 1.0);
    c.friction_velocity = env("KF_PROBE_EPS", c.friction_velocity);
  }
  if (env("KF_PROBE_DIRECT", 0)) scene.cloth->solver = "direct";
  scene.cloth->contact_ramp = env("KF_PROBE_RAMP", scene.cloth->contact_ramp);
  scene.controls.kind = ControlKind::kPerFrame;
  scene.controls.from_frame = 0;
  const auto sys = make_system(scene, scene.time.h());
  Problem problem(scene, scene.time, *sys);
  const VecX z = problem.initial_guess();
  const double phi0 = problem.evaluate(z, nullptr);
  if (hold) sys->hold_step_schedule(sys->step_schedule());
  const std::vector<VecX> x0 = problem.rollout().x;
  std::mt19937_64 rng(12);
  std::normal_distribution<double> normal;
  VecX dir(z.size());
  for (int i = 0; i < z.size(); ++i) dir[i] = normal(rng);
  dir /= dir.norm();
  std::printf("phi0 %.17g\n", phi0);
  const double ss[] = {1e-14, 1e-13, 1e-12, 1e-11, 1e-10, 1e-9, -1e-9, 2e-9, 1e-8, 1e-7, 1e-6};
  std::vector<std::vector<VecX>> xs;
  for (double s : ss) {
    const double phi = problem.evaluate(VecX(z + s * dir), nullptr);
    std::printf("s %8.1e phi %.17g rel %.3e\n", s, phi, (phi - phi0) / phi0);
    xs.push_back(problem.rollout().x);
  }
  // Per step: |x(s)-x(0)| at s = 1e-9, -1e-9, 1e-8, and the asymmetry |x(+s)+x(-s)-2x(0)|.
  for (size_t n = 0; n < x0.size(); ++n) {
    const double dp = (xs[5][n] - x0[n]).norm(), dm = (xs[6][n] - x0[n]).norm(), d8 = (xs[8][n] - x0[n]).norm();
    const double asym = (xs[5][n] + xs[6][n] - 2 * x0[n]).norm();
    const double d14 = (xs[0][n] - x0[n]).norm(), d13 = (xs[1][n] - x0[n]).norm();
    std::printf("n %3zu |d14| %.3e |d13|/10 %.3e |d+9| %.3e |d-9| %.3e |d-8|/10 %.3e asym %.3e\n", n, d14, d13 / 10, dp, dm, d8 / 10, asym);
  }
}

}  // namespace
}  // namespace kf

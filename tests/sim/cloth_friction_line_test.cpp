// φ along a line through the controls of a sheet dropped with friction onto a torus and the ground (a reduced
// drop-collider scene of the generated suite): with the split schedule held as the strategy holds it, a
// step of 1e-9 moves φ by no more than its derivative says. Friction that reversed the slip of sliding
// particles made this run part from its neighbours several-fold per step: φ moved by several times
// itself for steps of 1e-9 (and 1e-12).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "opt/gradcheck.h"
#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/make_system.h"
#include "gradient_test_helpers.h"

namespace kf {
namespace {

// solver: "pcg" as the suite's scenes (the line test), "direct" for a gradient exact to round-off.
Scene dropped_on_torus(const std::string& solver) {
  return parse_scene(R"({
    "time": {"fps": 30, "frames": 24},
    "cloth": {"nx": 8, "ny": 8, "width": 1.05, "height": 1.05, "mass": 0.58,
              "origin": [-0.25, 1.19, -0.41], "u_axis": [1, 0, 0], "v_axis": [0, 0, 1], "solver": ")" + solver + R"(",
              "colliders": [{"type": "torus", "center": [0.21, 1.04, -0.14], "axis": [0, 1, 0], "radius": 0.32,
                             "tube_radius": 0.04, "friction": 0.33},
                            {"type": "ground", "friction": 0.34}]},
    "controls": {"kind": "per_frame"},
    "objectives": [{"type": "position", "frame": 12, "particles": [0], "targets": [[-0.1, 1.0, -0.35]]},
                   {"type": "center_of_mass", "frame": 24, "target": [0.2, 0.8, -0.1]}]
  })",
                     "drop_collider_reduced.json");
}

// φ at z and along a random unit direction d at steps s = ±1e-9 (the diagnosis probe's scale) and ±1e-7.
struct Line {
  double phi = 0, plus9 = 0, minus9 = 0, plus7 = 0, minus7 = 0;
};

Line line_through(Problem& problem, System& sys, const VecX& z) {
  Line l;
  sys.release_step_schedule();
  l.phi = problem.evaluate(z, nullptr);
  sys.hold_step_schedule(sys.step_schedule());  // as each stage of the strategy holds it
  std::mt19937_64 rng(12);
  std::normal_distribution<double> normal;
  VecX d(z.size());
  for (int i = 0; i < z.size(); ++i) d[i] = normal(rng);
  d /= d.norm();
  const double scale = std::max(1.0, z.cwiseAbs().maxCoeff());
  l.plus9 = problem.evaluate(VecX(z + 1e-9 * scale * d), nullptr);
  l.minus9 = problem.evaluate(VecX(z - 1e-9 * scale * d), nullptr);
  l.plus7 = problem.evaluate(VecX(z + 1e-7 * scale * d), nullptr);
  l.minus7 = problem.evaluate(VecX(z - 1e-7 * scale * d), nullptr);
  EXPECT_FALSE(problem.last_diverged());
  return l;
}

TEST(ClothFrictionLine, NoJumpAlongALineAtZeroAndPerturbedControls) {
  const Scene scene = dropped_on_torus("pcg");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  for (double perturb : {0.0, 0.3}) {
    const VecX z = test::perturbed_controls(problem, perturb * problem.control_scale(), 5);
    const Line l = line_through(problem, *sys, z);
    std::printf("perturb %g: phi %.10g, moves %.2e %.2e at 1e-9, %.2e %.2e at 1e-7 (of itself)\n", perturb, l.phi,
                (l.plus9 - l.phi) / l.phi, (l.minus9 - l.phi) / l.phi, (l.plus7 - l.phi) / l.phi,
                (l.minus7 - l.phi) / l.phi);
    ASSERT_GT(l.phi, 0);
    EXPECT_LE(std::abs(l.plus9 - l.phi), 1e-6 * l.phi) << "perturb " << perturb;
    EXPECT_LE(std::abs(l.minus9 - l.phi), 1e-6 * l.phi) << "perturb " << perturb;
    // Smooth: at 1e-9 the two sides are each other's opposite (curvature and round-off far below the slope),
    // and at 1e-7 φ moves within a few times a hundredfold of that.
    const double slope9 = (l.plus9 - l.minus9) / 2, slope7 = (l.plus7 - l.minus7) / 2;
    EXPECT_LE(std::abs(l.plus9 + l.minus9 - 2 * l.phi), 0.05 * std::abs(slope9) + 1e-15 * l.phi) << "perturb " << perturb;
    EXPECT_LE(std::abs(slope7), 300 * std::abs(slope9)) << "perturb " << perturb;
  }
}

// The same run's exact adjoint against central differences at two step sizes that agree, at zero and
// perturbed controls, with the schedule held.
TEST(ClothFrictionLine, GradientMatchesFiniteDifferences) {
  const Scene scene = dropped_on_torus("direct");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  for (double perturb : {0.0, 0.3}) {
    const VecX z = test::perturbed_controls(problem, perturb * problem.control_scale(), 7);
    sys->release_step_schedule();
    problem.evaluate(z, nullptr);
    sys->hold_step_schedule(sys->step_schedule());
    const GradcheckResult r = gradcheck(problem, z, {.samples = 16, .eps = 1e-4, .seed = 5});
    std::printf("perturb %g: max_rel_error %.2e, fd_spread %.2e, %d checked, %d kinks\n", perturb, r.max_rel_error,
                r.fd_spread, r.checked, r.kinks);
    ASSERT_GT(r.grad_norm, 0);
    EXPECT_GE(r.checked, 14) << "perturb " << perturb;
    EXPECT_LE(r.max_rel_error, 1e-5) << "perturb " << perturb;
  }
}

}  // namespace
}  // namespace kf

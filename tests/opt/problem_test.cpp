#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>

#include "opt/gradcheck.h"
#include "opt/optimizer.h"
#include "opt/problem.h"
#include "scene/scene.h"
#include "toy_system.h"

namespace kf {
namespace {

// A cloth-typed scene (3-D controls) whose particle count matches the toy system: 2 x 2 = 4 particles.
Scene toy_scene(const std::string& controls, int substeps, int from_frame = 0) {
  const std::string text = R"({
    "time": {"fps": 10, "substeps": )" + std::to_string(substeps) + R"(, "frames": 12},
    "cloth": {"nx": 2, "ny": 2},
    "objectives": [
      {"type": "position", "frame": 6, "particles": [3], "targets": [[2.0, 1.0, 0.5]], "weight": 3},
      {"type": "velocity", "frame": 12, "targets": [[0.1, 0.0, 0.0]]},
      {"type": "center_of_mass", "frame": 12, "target": [1.0, 0.5, -0.5], "weight": 2},
      {"type": "arch", "frame": 9, "axis_point": [1, 0, 0], "axis": [0, 0, 1], "radius": 1.2}
    ],
    "controls": {"kind": ")" + controls + R"(", "alpha": 0.01, "from_frame": )" + std::to_string(from_frame) + R"(}
  })";
  return parse_scene(text, "toy.json");
}

class ProblemGradient : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

TEST_P(ProblemGradient, AdjointMatchesFiniteDifferences) {
  const auto [kind, substeps] = GetParam();
  Scene scene = toy_scene(kind, substeps);
  test::ToySystem sys(4, scene.time.h());
  Problem problem(scene, scene.time, sys);
  VecX z = problem.initial_guess() + 0.3 * VecX::Random(problem.size());
  const GradcheckResult r = gradcheck(problem, z, {.samples = 60, .eps = 1e-3, .seed = 3});
  ASSERT_GT(r.grad_norm, 1e-3);  // not trivially zero
  EXPECT_GE(r.checked, std::min(11, problem.size()));  // the rigid throw has only six
  EXPECT_LT(r.max_rel_error, 1e-6) << "cosine " << r.cosine;
  EXPECT_GT(r.cosine, 1 - 1e-10);
}

INSTANTIATE_TEST_SUITE_P(Controls, ProblemGradient,
                         ::testing::Values(std::make_tuple("per_step", 1), std::make_tuple("per_step", 3),
                                           std::make_tuple("per_frame", 3), std::make_tuple("initial_velocity", 2),
                                           std::make_tuple("initial_rigid_velocity", 2)));

// Lattice forces (a coarse stage's controls, never a scene's own): the adjoint's chain rule through the
// lattice at perturbed controls, with 1 and 3 substeps.
TEST(Problem, LatticeForcesGradientMatchesFiniteDifferences) {
  for (int substeps : {1, 3}) {
    Scene scene = toy_scene("per_frame", substeps, 2);
    scene.controls.kind = ControlKind::kPerFrameLattice;
    test::ToySystem sys(4, scene.time.h());
    Problem problem(scene, scene.time, sys);
    ASSERT_EQ(problem.size(), (12 - 2) * 9 * 3);
    VecX z = problem.initial_guess() + 0.3 * VecX::Random(problem.size());
    const GradcheckResult r = gradcheck(problem, z, {.samples = 60, .eps = 1e-3, .seed = 3});
    ASSERT_GT(r.grad_norm, 1e-3);
    EXPECT_GE(r.checked, 11);
    EXPECT_LT(r.max_rel_error, 1e-6) << "substeps " << substeps << ", cosine " << r.cosine;
  }
}

// A lattice stage's forces carried into the per-particle stage after it: the particles feel the same force
// at every step and the effort is the same; carried back, the lattice's own values return (least squares of
// a field the lattice spans). A 5 x 5 sheet so every node has particles around it.
TEST(Problem, LatticeForcesCarryOverToPerParticleForcesExactly) {
  TimeSpec t;
  t.fps = 10, t.substeps = 2, t.frames = 6;
  VecX x0(3 * 25);
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 5; ++i) x0.segment<3>(3 * (5 * j + i)) = Vec3(0.1 * i, 1.0, 0.2 * j);
  ControlSpec lattice_spec, particle_spec;
  lattice_spec.kind = ControlKind::kPerFrameLattice;
  particle_spec.kind = ControlKind::kPerFrame;
  lattice_spec.from_frame = particle_spec.from_frame = 2;
  const Controls lattice(lattice_spec, t, 25, false, x0, VecX::Zero(75));
  const Controls particles(particle_spec, t, 25, false, x0, VecX::Zero(75));
  ASSERT_EQ(lattice.size(), 4 * 9 * 3);
  const VecX zl = VecX::LinSpaced(lattice.size(), -1, 2);
  const VecX zp = particles.remap_from(lattice.per_particle_forces(zl), t, 2);
  ASSERT_EQ(zp.size(), particles.size());
  VecX ul, up;
  for (int n = 0; n < t.steps(); ++n) {
    lattice.force_at(zl, n, ul);
    particles.force_at(zp, n, up);
    EXPECT_LT((ul - up).lpNorm<Eigen::Infinity>(), 1e-14) << "step " << n;
  }
  VecX gl = VecX::Zero(lattice.size()), gp = VecX::Zero(particles.size());
  EXPECT_NEAR(lattice.effort(zl, gl), particles.effort(zp, gp), 1e-12);
  const VecX back = lattice.remap_from(zp, t, 2);
  EXPECT_LT((back - zl).lpNorm<Eigen::Infinity>(), 1e-9);
  // A window grown backwards on the lattice: the new frames start without force.
  ControlSpec earlier = lattice_spec;
  earlier.from_frame = 0;
  const Controls grown(earlier, t, 25, false, x0, VecX::Zero(75));
  const VecX zg = grown.remap_from(lattice.per_particle_forces(zl), t, 2);
  for (int n = 0; n < t.steps(); ++n) {
    grown.force_at(zg, n, up);
    lattice.force_at(zl, n, ul);
    EXPECT_LT((ul - up).lpNorm<Eigen::Infinity>(), 1e-9) << "step " << n;
  }
}

TEST(Problem, PerFrameForcesAreHeldOverSubsteps) {
  Scene scene = toy_scene("per_frame", 4);
  test::ToySystem sys(4, scene.time.h());
  Controls c(scene.controls, scene.time, 4, false, VecX::Zero(12), VecX::Zero(12));
  EXPECT_EQ(c.size(), 12 * 12);
  VecX z = VecX::LinSpaced(c.size(), 0, 1), v0;
  std::vector<VecX> U;
  c.expand(z, v0, U);
  ASSERT_EQ(U.size(), 48u);
  EXPECT_EQ(U[4], U[7]);
  EXPECT_NE(U[3], U[4]);
}

// Forces from frame 5 on: none before, the gradient (whose adjoint pass stops at step 5 * substeps) still
// exact, per-step forces remapped between substep counts within the window.
TEST(Problem, ForcesFromAFrameOnAreZeroBeforeItAndTheirGradientIsExact) {
  for (const std::string kind : {"per_frame", "per_step"}) {
    Scene scene = toy_scene(kind, 3, 5);
    test::ToySystem sys(4, scene.time.h());
    Problem problem(scene, scene.time, sys);
    const int blocks = kind == "per_frame" ? 12 - 5 : 3 * (12 - 5);
    ASSERT_EQ(problem.size(), blocks * 4 * 3) << kind;
    Controls c(scene.controls, scene.time, 4, false, VecX::Zero(12), VecX::Zero(12));
    VecX u;
    c.force_at(VecX::Ones(c.size()), 14, u);
    EXPECT_TRUE(u.isZero(0.0)) << kind;
    c.force_at(VecX::Ones(c.size()), 15, u);
    EXPECT_TRUE(u.isOnes(0.0)) << kind;
    VecX z = problem.initial_guess() + 0.3 * VecX::Random(problem.size());
    const GradcheckResult r = gradcheck(problem, z, {.samples = 40, .eps = 1e-3, .seed = 5});
    ASSERT_GT(r.grad_norm, 1e-3) << kind;
    EXPECT_LT(r.max_rel_error, 1e-6) << kind << ": cosine " << r.cosine;
  }
  TimeSpec fine;
  fine.fps = 10, fine.substeps = 4, fine.frames = 12;
  TimeSpec coarse = fine;
  coarse.substeps = 2;
  ControlSpec spec;
  spec.kind = ControlKind::kPerStep;  // steps, not frames, are remapped here
  spec.from_frame = 5;
  const Controls cf(spec, fine, 1, false, VecX::Zero(3), VecX::Zero(3));
  const Controls cc(spec, coarse, 1, false, VecX::Zero(3), VecX::Zero(3));
  const VecX zc = VecX::LinSpaced(cc.size(), 1, double(cc.size()));
  const VecX zf = cf.remap_from(zc, coarse, 5);
  ASSERT_EQ(zf.size(), cf.size());
  VecX uf, uc;
  for (int n = 20; n < 48; ++n) {  // fine step n lies in coarse step n / 2
    cf.force_at(zf, n, uf);
    cc.force_at(zc, n / 2, uc);
    EXPECT_EQ(uf, uc) << "step " << n;
  }
}

// A window grown backwards: the forces of the later window carry over unchanged, the new frames start
// without force; and back again (a shorter window keeps the forces of its own frames).
TEST(Problem, RemapBetweenWindowsKeepsEachFramesForce) {
  TimeSpec t;
  t.fps = 10, t.substeps = 2, t.frames = 12;
  for (ControlKind kind : {ControlKind::kPerStep, ControlKind::kPerFrame}) {
    ControlSpec late, early;
    late.kind = early.kind = kind;
    late.from_frame = 8;
    early.from_frame = 3;
    const Controls cl(late, t, 2, false, VecX::Zero(6), VecX::Zero(6));
    const Controls ce(early, t, 2, false, VecX::Zero(6), VecX::Zero(6));
    const VecX zl = VecX::LinSpaced(cl.size(), 1, double(cl.size()));
    const VecX ze = ce.remap_from(zl, t, 8);
    ASSERT_EQ(ze.size(), ce.size());
    VecX ue, ul;
    for (int n = 0; n < t.steps(); ++n) {
      ce.force_at(ze, n, ue);
      cl.force_at(zl, n, ul);
      EXPECT_EQ(ue, ul) << control_kind_name(kind) << " step " << n;
    }
    const VecX back = cl.remap_from(ze, t, 3);
    EXPECT_EQ(back, zl) << control_kind_name(kind);
  }
}

TEST(Problem, PlanarControlsHaveNoVerticalComponent) {
  TimeSpec t;
  t.frames = 3;
  ControlSpec spec;
  spec.kind = ControlKind::kPerStep;
  Controls c(spec, t, 5, true, VecX::Zero(15), VecX::Zero(15));
  EXPECT_EQ(c.size(), 3 * 5 * 2);
  VecX v0;
  std::vector<VecX> U;
  c.expand(VecX::Ones(c.size()), v0, U);
  for (const auto& u : U)
    for (int i = 0; i < 5; ++i) EXPECT_EQ(u[3 * i + 1], 0.0);
}

// A flat 5 x 4 sheet tilted out of every coordinate plane, its velocities from a 3 x 3 lattice.
TEST(Problem, LatticeVelocitiesHoldARigidThrowExactlyAndGatherIsTheirTranspose) {
  const Vec3 u = Vec3(1, 0.2, 0.1).normalized(), v = Vec3(-0.1, 0.3, 1).normalized();
  VecX x0(3 * 20), v0_scene(3 * 20);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 5; ++i) {
      x0.segment<3>(3 * (j * 5 + i)) = Vec3(0.5, 1, -0.2) + 0.1 * i * u + 0.1 * j * v;
      v0_scene.segment<3>(3 * (j * 5 + i)) = Vec3(0.3, -0.1, 0.2);
    }
  TimeSpec t;
  ControlSpec rigid_spec, lattice_spec;
  rigid_spec.kind = ControlKind::kInitialRigidVelocity;
  lattice_spec.kind = ControlKind::kInitialLatticeVelocity;
  const Controls rigid(rigid_spec, t, 20, false, x0, v0_scene), lattice(lattice_spec, t, 20, false, x0, v0_scene);
  ASSERT_EQ(lattice.size(), 27);
  // A rigid throw's velocities are affine over the sheet's plane: bilinear interpolation holds them exactly.
  VecX v_rigid, v_lattice;
  rigid.initial_velocity((VecX(6) << 0.4, 2.0, -0.7, 1.5, -0.3, 2.2).finished(), v_rigid);
  lattice.initial_velocity(lattice.from_initial_velocity(v_rigid), v_lattice);
  EXPECT_LT((v_lattice - v_rigid).norm(), 1e-10 * v_rigid.norm());
  // A field that is not bilinear over the lattice's cells is not.
  VecX v_wavy = v0_scene;
  for (int i = 0; i < 20; ++i) v_wavy[3 * i + 1] += std::sin(7.0 * i);
  lattice.initial_velocity(lattice.from_initial_velocity(v_wavy), v_lattice);
  EXPECT_GT((v_lattice - v_wavy).norm(), 0.1);
  // <W z, dv> = <z, W^T dv>: the gradient the optimiser gets is the transpose of the map it steers.
  const VecX z = VecX::Random(27), dv = VecX::Random(60);
  VecX v_z, dz = VecX::Zero(27);
  std::vector<VecX> U, dU(t.steps(), VecX::Zero(60));
  lattice.expand(z, v_z, U);
  lattice.gather(dU, dv, dz);
  EXPECT_NEAR((v_z - v0_scene).dot(dv), z.dot(dz), 1e-12);
}

// The toy chain with nearly free control effort, and 200 evaluations for L-BFGS.
Scene cheap_effort_scene() {
  Scene scene = toy_scene("per_frame", 2);
  scene.controls.alpha = 1e-6;
  return scene;
}
struct CheapEffortToy {
  Scene scene = cheap_effort_scene();
  test::ToySystem sys{4, scene.time.h()};
  Problem problem{scene, scene.time, sys};
  OptimizerSpec spec = [] {
    OptimizerSpec s;
    s.max_evaluations = 200;
    return s;
  }();
};

TEST(Optimizer, ReducesTheObjectiveByOrdersOfMagnitude) {
  CheapEffortToy toy;
  Problem& problem = toy.problem;
  const VecX z0 = problem.initial_guess();
  const double phi0 = problem.evaluate(z0, nullptr);
  const OptimizeResult r = minimize(problem, toy.spec, z0);
  EXPECT_LT(r.phi, 1e-3 * phi0) << r.status;
  EXPECT_GT(r.evaluations, 2);
}

TEST(Optimizer, AStopAskedForDuringTheLastEvaluationIsAnInterruption) {
  // NLopt may end on the evaluation during which the stop arrived without asking for another (its
  // line search gives up, it converges, or its own limit is reached): the run was still told to stop, and
  // says only that. Here NLopt's limit of one evaluation ends it right after the stop is asked for.
  Scene scene = toy_scene("per_frame", 2);
  test::ToySystem sys(4, scene.time.h());
  Problem problem(scene, scene.time, sys);
  OptimizerSpec spec;
  spec.max_evaluations = 1;
  std::atomic<bool> stop{false};
  const OptimizeResult r = minimize(problem, spec, problem.initial_guess(), [&](const EvaluationRecord&) { stop = true; }, &stop);
  EXPECT_EQ(r.evaluations, 1);
  EXPECT_TRUE(r.interrupted);
  EXPECT_EQ(r.status, "interrupted");
  // Without a stop the same run ends at its limit.
  std::atomic<bool> no_stop{false};
  const OptimizeResult whole = minimize(problem, spec, problem.initial_guess(), {}, &no_stop);
  EXPECT_FALSE(whole.interrupted);
  EXPECT_EQ(whole.status, "evaluation limit reached");
}

// optimizer.stop_when_reached's predicate: asked only after evaluations that improve on the best point, with
// the problem holding that point's rollout, and a true answer ends the run there, with no evaluation after it.
TEST(Optimizer, AReachedAnswerEndsTheRunAtTheBestPointItWasAskedAbout) {
  CheapEffortToy toy;
  Problem& problem = toy.problem;
  const OptimizerSpec& spec = toy.spec;
  const VecX z0 = problem.initial_guess();
  const OptimizeResult whole = minimize(problem, spec, z0);
  const double target = 1e-2 * whole.history.front().phi;
  // The first evaluation of the whole run below the target, and the best before it: the same path until then.
  int first_below = 0, improving = 0;
  double best = std::numeric_limits<double>::infinity();
  for (const EvaluationRecord& r : whole.history) {
    if (r.diverged || !(r.phi < best)) continue;
    best = r.phi;
    ++improving;
    if (r.phi < target) {
      first_below = r.evaluation;
      break;
    }
  }
  ASSERT_GT(first_below, 2);
  ASSERT_LT(first_below, whole.evaluations);
  int asked = 0;
  const auto reached = [&] {
    ++asked;
    double phi = 0;
    for (const auto& [name, value] : problem.breakdown()) phi += value;
    return phi < target;
  };
  const OptimizeResult r = minimize(problem, spec, z0, {}, nullptr, nullptr, reached);
  EXPECT_EQ(r.evaluations, first_below);
  EXPECT_EQ(r.status, kKeyframesReached);
  EXPECT_TRUE(r.reached);
  EXPECT_FALSE(r.interrupted);
  EXPECT_LT(r.phi, target);
  EXPECT_EQ(r.phi, whole.history[first_below - 1].phi);
  EXPECT_EQ(asked, improving);  // not after the evaluations that did not improve
}

// The toy chain with heavy keyframes and cheap effort, and the largest control force of its optimum
// without a limit: limits above it leave the optimum reachable while the line search's long steps cross them.
Scene heavy_toy_scene() {
  Scene scene = toy_scene("per_frame", 2);
  scene.controls.alpha = 1e-6;
  for (auto& o : scene.objectives) o.weight *= 1e4;
  return scene;
}
double free_optimum_peak(const Scene& scene) {
  test::ToySystem free_sys(4, scene.time.h());
  Problem free_problem(scene, scene.time, free_sys);
  OptimizerSpec spec;
  spec.max_evaluations = 150;
  return minimize(free_problem, spec, free_problem.initial_guess()).z.cwiseAbs().maxCoeff();
}

TEST(Optimizer, RecoversFromDivergedTrialSteps) {
  // Controls above a limit blow the toy system up. The limit sits above the optimum's largest force,
  // so the optimum is reachable, but the line search's long trial steps cross it.
  const Scene scene = heavy_toy_scene();
  const double peak = free_optimum_peak(scene);
  test::ToySystem sys(4, scene.time.h(), 1.5 * peak);
  Problem problem(scene, scene.time, sys);
  VecX big = VecX::Constant(problem.size(), 10 * peak), g(problem.size());
  const double phi_bad = problem.evaluate(big, &g);
  EXPECT_TRUE(problem.last_diverged());
  EXPECT_TRUE(std::isfinite(phi_bad));
  EXPECT_TRUE(g.allFinite());
  const VecX z0 = problem.initial_guess();
  const double phi0 = problem.evaluate(z0, nullptr);
  EXPECT_FALSE(problem.last_diverged());
  OptimizerSpec spec;
  spec.max_evaluations = 150;
  spec.first_step = 0;  // NLopt's own first step, the whole gradient: it crosses the limit
  int diverged = 0;
  const OptimizeResult r = minimize(problem, spec, z0, [&](const EvaluationRecord& e) { diverged += e.diverged; });
  EXPECT_TRUE(std::isfinite(r.phi));
  EXPECT_GT(diverged, 0) << "no trial step diverged: the test does not exercise recovery";
  EXPECT_LT(r.phi, 0.5 * phi0) << r.status;
  EXPECT_EQ(r.capped_trials, 0) << "a trial that only diverged must not limit the reach of later ones";
}

// A tighter limit, once said to be an instability and once only a divergence. As an instability, later
// trials farther from the best point than half a refused one's distance are refused without simulating
// them: the run gets as far with fewer simulations. Every evaluation in its history was simulated; the
// capped trials are counted apart.
TEST(Optimizer, TrialsPastAnUnstableOnesReachAreRefusedWithoutSimulating) {
  const Scene scene = heavy_toy_scene();
  const double peak = free_optimum_peak(scene);
  OptimizerSpec spec;
  spec.max_evaluations = 150;
  spec.first_step = 0;
  OptimizeResult runs[2];
  int unstable = 0;
  double phi0 = 0;
  for (const bool is_unstable : {false, true}) {
    test::ToySystem sys(4, scene.time.h(), 1.1 * peak, is_unstable);
    Problem problem(scene, scene.time, sys);
    phi0 = problem.evaluate(problem.initial_guess(), nullptr);
    runs[is_unstable] = minimize(problem, spec, problem.initial_guess(),
                                 [&](const EvaluationRecord& e) { unstable += e.unstable; });
  }
  const OptimizeResult &plain = runs[0], &capped = runs[1];
  std::printf("unstable trials %d, capped %d; evaluations %d against %d; phi %.6g against %.6g (from %.6g)\n",
              unstable, capped.capped_trials, capped.evaluations, plain.evaluations, capped.phi, plain.phi, phi0);
  EXPECT_GT(unstable, 0) << "no trial was refused as unstable: the test does not exercise the reach";
  EXPECT_GT(capped.capped_trials, 0);
  EXPECT_EQ(plain.capped_trials, 0);
  EXPECT_EQ(int(capped.history.size()), capped.evaluations);
  EXPECT_LT(capped.evaluations, plain.evaluations);
  EXPECT_LE(capped.phi, 1.01 * plain.phi) << capped.status;
  EXPECT_LT(capped.phi, 0.05 * phi0) << capped.status;
}

}  // namespace
}  // namespace kf

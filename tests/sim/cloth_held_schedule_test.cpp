// A held split pattern (ClothSystem::hold_schedule): the steps repeat the substeps a run's energy check chose,
// so the rollout is the same function as that run's at its own controls and a smooth one around them.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

#include "opt/gradcheck.h"
#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/cloth/cloth_system.h"
#include "sim/make_system.h"
#include "split_curtain.h"

namespace kf {
namespace {

// The curtain of split_curtain.h, solved to 1e-13: at the default PCG tolerance (1e-8) the solves' own error
// shows in the gradient at about 3e-5.
Scene curtain() { return test::split_curtain(R"(, "cg_tolerance": 1e-13)", "[0, 1, 2, 3, 4, 5, 6, 7]"); }

// The curtain's system and problem, simulated once, adaptively, under random forces of about the
// particles' weight: a perturbed control, not the start.
class ClothHeldSchedule : public ::testing::Test {
 protected:
  ClothHeldSchedule() {
    std::srand(11);
    z = problem.initial_guess() + 0.3 * problem.control_scale() * VecX::Random(problem.size());
    adaptive = problem.evaluate(z, nullptr);
    adaptive_end = problem.rollout().x.back();
  }
  const Scene scene = curtain();
  std::unique_ptr<System> sys = make_system(scene);
  ClothSystem& cloth = *cloth_of(*sys);
  Problem problem{scene, scene.time, *sys};
  VecX z, adaptive_end;
  double adaptive = 0;
};

TEST_F(ClothHeldSchedule, RepeatsTheRunThatRecordedIt) {
  const ClothSystem::StepSchedule recorded = cloth.schedule();
  ASSERT_EQ(int(recorded.size()), scene.time.steps());
  ASSERT_GT(test::split_steps(recorded), 2) << "the curtain should need split steps";
  cloth.hold_schedule(recorded);
  EXPECT_EQ(problem.evaluate(z, nullptr), adaptive);
  EXPECT_EQ(problem.rollout().x.back(), adaptive_end);
  EXPECT_EQ(cloth.schedule(), recorded);  // a held run records nothing
}

TEST_F(ClothHeldSchedule, OverridesTheEnergyCheck) {
  ASSERT_GT(test::split_steps(cloth.schedule()), 2);
  // Every step held whole: no step splits, and the motion differs from the checked one.
  cloth.hold_schedule(ClothSystem::StepSchedule(scene.time.steps(), std::vector<std::uint8_t>{0}));
  problem.evaluate(z, nullptr);
  for (const auto& [name, value] : sys->run_stats())
    if (name == "split_steps") EXPECT_EQ(value, 0);
  EXPECT_GT((problem.rollout().x.back() - adaptive_end).norm(), 1e-9);
  // Released, the check decides again and splits as before.
  cloth.release_schedule();
  problem.evaluate(z, nullptr);
  EXPECT_EQ(problem.rollout().x.back(), adaptive_end);
}

// The exact adjoint of a held rollout is its gradient: central differences at two step sizes agree with
// it at a perturbed control where steps are split, and no sample meets a jump.
TEST_F(ClothHeldSchedule, GradientMatchesFiniteDifferencesWithSplitSteps) {
  ASSERT_GT(test::split_steps(cloth.schedule()), 2);
  cloth.hold_schedule(cloth.schedule());
  for (const double eps : {1e-4, 3e-5}) {
    const GradcheckResult r = gradcheck(problem, z, {.samples = 24, .eps = eps, .seed = 5});
    std::printf("held, eps %.0e: checked %d, kinks %d, max_rel_error %.2e, cosine %.12f\n", eps, r.checked, r.kinks,
                r.max_rel_error, r.cosine);
    ASSERT_GT(r.grad_norm, 1e-6);
    EXPECT_EQ(r.kinks, 0);
    EXPECT_GE(r.checked, 20);
    EXPECT_LT(r.max_rel_error, 1e-6);
  }
}

// Released, a system steps as one that never held a pattern: a run's uncontrolled motion does not depend on
// what the optimiser evaluated before it.
TEST_F(ClothHeldSchedule, ReleasedRunsAsIfNeverHeld) {
  auto fresh = make_system(scene);
  Problem fresh_problem(scene, scene.time, *fresh);
  const double expected = fresh_problem.evaluate(fresh_problem.initial_guess(), nullptr);
  const VecX expected_end = fresh_problem.rollout().x.back();

  cloth.hold_schedule(cloth.schedule());
  VecX g(problem.size());
  problem.evaluate(z, &g);
  problem.evaluate(0.5 * z, &g);
  cloth.release_schedule();
  EXPECT_EQ(problem.evaluate(problem.initial_guess(), nullptr), expected);
  EXPECT_EQ(problem.rollout().x.back(), expected_end);
}

}  // namespace
}  // namespace kf

// The optimisation strategy's pieces: the first trial step in the controls' units, and the stages
// (windows grown backwards from the last keyframe, a rigid throw before per-particle velocities).
#include <gtest/gtest.h>

#include <cmath>

#include "opt/optimizer.h"
#include "opt/problem.h"
#include "opt/throw_search.h"
#include "opt/windows.h"
#include "core/error.h"
#include "scene/scene.h"
#include "sim/make_system.h"
#include "toy_system.h"

namespace kf {
namespace {

Scene strategy_scene(const std::string& body, const std::string& controls, const std::string& optimizer = "{}") {
  const std::string y = body.find("\"flock\"") != std::string::npos ? "0" : "0.1";  // a flock's targets are on the ground
  return parse_scene(R"({"time": {"fps": 30, "substeps": 2, "frames": 30}, )" + body + R"(,
    "objectives": [{"type": "center_of_mass", "frame": 28, "target": [0.3, )" + y + R"(, 0.2], "weight": 1e8},
                   {"type": "center_of_mass", "frame": 12, "target": [0.1, )" + y + R"(, 0.1]}],
    "controls": )" + controls + R"(, "optimizer": )" + optimizer + "}",
                     "strategy.json");
}

const char* kCloth = R"("cloth": {"nx": 2, "ny": 2})";

// L-BFGS's first trial step on a steep start: the second evaluation of the run, compared with φ evaluated
// here at z0 - c g for the step c the first_step asks for.
struct FirstTrial {
  double grad_norm = 0, phi0 = 0, trial_phi = 0, expected_phi = 0;
};

FirstTrial first_trial(double first_step) {
  Scene scene = strategy_scene(kCloth, R"({"kind": "per_frame", "alpha": 1e-6})");
  test::ToySystem sys(4, scene.time.h());
  Problem problem(scene, scene.time, sys);
  FirstTrial t;
  const VecX z0 = problem.initial_guess();
  VecX g(problem.size());
  t.phi0 = problem.evaluate(z0, &g);
  t.grad_norm = g.norm();
  // The whole gradient without a first_step; else a step of first_step RMS per variable along it.
  const double c = first_step > 0 ? first_step * std::sqrt(double(z0.size())) / t.grad_norm : 1.0;
  t.expected_phi = problem.evaluate(z0 - c * g, nullptr);
  OptimizerSpec spec;
  spec.max_evaluations = 2;  // NLopt checks it between iterations, so the first line search may go on
  spec.first_step = first_step;
  const OptimizeResult r = minimize(problem, spec, z0);
  EXPECT_GE(r.history.size(), 2u);
  if (r.history.size() >= 2) t.trial_phi = r.history[1].phi;
  return t;
}

TEST(Optimizer, FirstTrialStepMovesControlsByFirstStepRms) {
  const FirstTrial t = first_trial(0.05);
  ASSERT_GT(t.grad_norm, 1e4);  // steep: NLopt's own first step would be the whole gradient
  EXPECT_LT(t.trial_phi, t.phi0);
  EXPECT_NEAR(t.trial_phi, t.expected_phi, 1e-9 * t.expected_phi);
}

TEST(Optimizer, UnscaledFirstTrialStepIsTheWholeGradient) {
  const FirstTrial t = first_trial(0);
  EXPECT_GT(t.trial_phi, 100 * t.phi0);  // it overshoots a steep start by orders of magnitude
  EXPECT_NEAR(t.trial_phi, t.expected_phi, 1e-9 * t.expected_phi);
}

TEST(Optimizer, AutomaticFirstStepIsTheMeanParticlesWeight) {
  Scene scene = strategy_scene(kCloth, R"({"kind": "per_frame"})");
  test::ToySystem sys(4, scene.time.h());
  EXPECT_DOUBLE_EQ(Problem(scene, scene.time, sys).control_scale(), 9.81 * 1.5);
  Scene thrown = strategy_scene(kCloth, R"({"kind": "initial_velocity"})");
  EXPECT_DOUBLE_EQ(Problem(thrown, thrown.time, sys).control_scale(), 1.0);
}

// A flock feels no gravity: its first trial step is scaled to its mass times 1 m/s^2, not to a weight.
TEST(Optimizer, FlocksFirstStepIsScaledToTheirMass) {
  const Scene flock = strategy_scene(R"("flock": {"agents": 4, "mass": 2, "spawn": {"radius": 3}})",
                                     R"({"kind": "per_frame"})");
  auto sys = make_system(flock);
  EXPECT_DOUBLE_EQ(Problem(flock, flock.time, *sys).control_scale(), 2.0);
  EXPECT_TRUE(plan_stages(flock).scaled_first_step);
  EXPECT_FALSE(plan_stages(strategy_scene(kCloth, R"({"kind": "per_frame"})", R"({"strategy": "single"})"))
                   .scaled_first_step);
}

std::vector<int> window_starts(const std::vector<StageSpec>& stages, int scene_from) {
  std::vector<int> starts;
  for (const auto& s : stages) starts.push_back(s.controls ? s.controls->from_frame : scene_from);
  return starts;
}

TEST(Strategy, ClothForcesGrowWindowsBackwardsFromEachKeyframeInTimeOrder) {
  // A force early in free flight moves the keyframe more than a late one: growth above 1, so a threshold
  // of 1 asks for windows.
  const Scene scene = strategy_scene(kCloth, R"({"kind": "per_frame"})", R"({"max_evaluations": 300, "window_growth": 1})");
  const StagePlan plan = plan_stages(scene);
  EXPECT_GT(plan.growth, 1);
  // Keyframes at frames 12 and 28: windows grown back from 12 (only it counts) on the lattice, then per
  // particle over its first window, then from 28 down to 12 (both count) the same way, then per particle
  // over the whole horizon.
  EXPECT_EQ(window_starts(plan.stages, 0), (std::vector<int>{7, 2, 0, 7, 23, 18, 12, 23, 0}));
  EXPECT_EQ(plan.judged_until, (std::vector<int>{12, 12, 12, 12, kAllKeyframes, kAllKeyframes, kAllKeyframes,
                                                 kAllKeyframes, kAllKeyframes}));
  for (size_t k = 0; k + 1 < plan.stages.size(); ++k)
    EXPECT_EQ(plan.stages[k].controls->kind, k == 3 || k == 7 ? ControlKind::kPerFrame : ControlKind::kPerFrameLattice)
        << "stage " << k;
  int budget = 0;
  for (const auto& s : plan.stages) {
    budget += s.max_evaluations;
    EXPECT_EQ(s.substeps, 2);
  }
  EXPECT_EQ(budget, 300);
  // Each keyframe's shortest lattice window (the tame gradient) shares half the budget; the other windows,
  // the per-particle ones included, the rest.
  EXPECT_EQ(plan.stages[0].max_evaluations, 75);
  EXPECT_EQ(plan.stages[4].max_evaluations, 75);
  EXPECT_EQ(plan.stages[1].max_evaluations, 21);
  EXPECT_EQ(plan.stages[3].max_evaluations, 21);
  EXPECT_EQ(plan.stages.back().max_evaluations, 24);
  EXPECT_FALSE(plan.stages.back().controls);  // the last stage optimises the scene's own controls
  EXPECT_TRUE(plan.scaled_first_step);
  EXPECT_NE(plan.why.find("windows to frame 12 from frames 7, 2, 0, then per particle from frame 7, then to frame 28 "
                          "(every keyframe) from frames 23, 18, 12, then per particle from frame 23 (all but the "
                          "per-particle ones on a 3 x 3 lattice of forces over the sheet), then one force per "
                          "particle from frame 0"),
            std::string::npos)
      << plan.why;
  // Per-step forces have no lattice: their windows are per particle. From frame 20 only the keyframe at 28
  // can be steered: its windows alone, the last the scene's own controls.
  const Scene late = strategy_scene(kCloth, R"({"kind": "per_step", "from_frame": 20})",
                                    R"({"window_frames": 3, "window_growth": 1})");
  const StagePlan late_plan = plan_stages(late);
  EXPECT_EQ(window_starts(late_plan.stages, 20), (std::vector<int>{25, 22, 20}));
  EXPECT_EQ(late_plan.stages.front().controls->kind, ControlKind::kPerStep);
  EXPECT_FALSE(late_plan.stages.back().controls);
  EXPECT_NE(late_plan.why.find("windows from frames 25, 22, 20 to frame 28"), std::string::npos) << late_plan.why;
  // The same scene below its threshold: one stage.
  const Scene tame = strategy_scene(kCloth, R"({"kind": "per_frame"})", R"({"window_growth": 1e12})");
  const StagePlan one = plan_stages(tame);
  EXPECT_EQ(one.stages.size(), 1u);
  EXPECT_EQ(one.growth, plan.growth);
  EXPECT_FALSE(one.scaled_first_step);  // a run the strategy leaves alone runs as it did without it
  EXPECT_TRUE(one.windows_on_early_end);     // ... unless its one stage stalls with evaluations left
  EXPECT_FALSE(plan.windows_on_early_end);
  // What a stalled stage leaves: the same windows sharing it, fewer where it does not fit them all.
  std::vector<int> until;
  const std::vector<StageSpec> after = window_stages(tame, 101, &until);
  EXPECT_EQ(window_starts(after, 0), (std::vector<int>{7, 2, 0, 7, 23, 12, 23, 0}));
  EXPECT_EQ(until, (std::vector<int>{12, 12, 12, 12, kAllKeyframes, kAllKeyframes, kAllKeyframes, kAllKeyframes}));
  int left = 0;
  for (const auto& s : after) left += s.max_evaluations;
  EXPECT_EQ(left, 101);
  EXPECT_EQ(after.front().max_evaluations, 25);
}

// A budget below what every window needs plans fewer windows (each keyframe keeps its shortest window and
// the one reaching down to where its windows end), not the same windows each cut short.
TEST(Strategy, ASmallBudgetPlansFewerWindows) {
  const Scene scene = strategy_scene(kCloth, R"({"kind": "per_frame"})", R"({"max_evaluations": 60, "window_growth": 1})");
  const StagePlan plan = plan_stages(scene);
  EXPECT_EQ(window_starts(plan.stages, 0), (std::vector<int>{7, 0, 23, 12, 0}));
  EXPECT_EQ(plan.judged_until, (std::vector<int>{12, 12, kAllKeyframes, kAllKeyframes, kAllKeyframes}));
  int budget = 0;
  for (const auto& s : plan.stages) {
    budget += s.max_evaluations;
    EXPECT_GE(s.max_evaluations, 10);  // the shortest windows 15, the others 10
  }
  EXPECT_EQ(budget, 60);
  // Middle windows go before the per-particle ones; a budget that fits them all keeps them all.
  const Scene more = strategy_scene(kCloth, R"({"kind": "per_frame"})", R"({"max_evaluations": 84, "window_growth": 1})");
  const StagePlan more_plan = plan_stages(more);
  EXPECT_EQ(window_starts(more_plan.stages, 0), (std::vector<int>{7, 0, 7, 23, 12, 23, 0}));
  EXPECT_EQ(more_plan.stages[2].controls->kind, ControlKind::kPerFrame);
  const Scene full = strategy_scene(kCloth, R"({"kind": "per_frame"})", R"({"max_evaluations": 108, "window_growth": 1})");
  EXPECT_EQ(plan_stages(full).stages.size(), 9u);
}

// A single keyframe: its lattice windows, one per-particle window over the first one's frames, then the whole
// horizon; per-step forces, whose windows are per particle already, get none.
TEST(Strategy, PerFrameForcesGetAPerParticleWindowAfterTheirLatticeWindows) {
  const Scene scene = parse_scene(R"({"time": {"fps": 30, "substeps": 2, "frames": 30}, "cloth": {"nx": 2, "ny": 2},
    "objectives": [{"type": "center_of_mass", "frame": 28, "target": [0.3, 0.1, 0.2]}],
    "controls": {"kind": "per_frame"}, "optimizer": {"window_growth": 1, "window_frames": 5}})",
                                  "single.json");
  const StagePlan plan = plan_stages(scene);
  EXPECT_EQ(window_starts(plan.stages, 0), (std::vector<int>{23, 18, 8, 0, 23, 0}));
  ASSERT_EQ(plan.stages.size(), 6u);
  EXPECT_EQ(plan.stages[4].controls->kind, ControlKind::kPerFrame);
  EXPECT_EQ(plan.stages[3].controls->kind, ControlKind::kPerFrameLattice);
  EXPECT_FALSE(plan.stages[5].controls);
  EXPECT_EQ(plan.stages[0].max_evaluations, 150);
  EXPECT_EQ(plan.stages[4].max_evaluations, 30);
  EXPECT_NE(plan.why.find("windows from frames 23, 18, 8, 0 to frame 28, then per particle from frame 23 (all but"),
            std::string::npos)
      << plan.why;
  Scene per_step = scene;
  per_step.controls.kind = ControlKind::kPerStep;
  std::vector<int> until;
  const std::vector<StageSpec> steps = window_stages(per_step, 300, &until);
  EXPECT_EQ(window_starts(steps, 0), (std::vector<int>{23, 18, 8, 0}));
  for (const auto& s : steps)
    if (s.controls) EXPECT_EQ(s.controls->kind, ControlKind::kPerStep);
}

// The growth is read from the gradient's frames: a keyframe's own frame's forces against earlier ones.
TEST(Strategy, GradientGrowthComparesFramesOfTheForceGradient) {
  const Scene scene = strategy_scene(kCloth, R"({"kind": "per_step", "from_frame": 4})");
  test::ToySystem sys(4, scene.time.h());
  Problem problem(scene, scene.time, sys);
  const VecX z = problem.initial_guess();
  VecX g(problem.size());
  problem.evaluate(z, &g);
  const long stride = 12, per_frame = 2 * stride;  // 4 particles x 3, two steps a frame
  double largest = 0;
  for (int f = 4; f < 30; ++f) largest = std::max(largest, g.segment((f - 4) * per_frame, per_frame).norm());
  const double ref = g.segment((27 - 4) * per_frame, per_frame).norm();
  EXPECT_NEAR(gradient_growth(problem, z, 27), largest / ref, 1e-12 * largest / ref);
}

TEST(Strategy, InitialVelocitiesStartFromASearchedRigidThrowThenALattice) {
  const Scene scene = strategy_scene(kCloth, R"({"kind": "initial_velocity", "alpha": 0.5})", R"({"max_evaluations": 90})");
  const StagePlan plan = plan_stages(scene);
  EXPECT_TRUE(plan.scaled_first_step);
  // The automatic search, at most twice the budget in throws.
  EXPECT_EQ(automatic_throw_count(scene.cloth->nx * scene.cloth->ny, scene.time.steps()), 512);
  EXPECT_EQ(plan.throw_search, 180);
  const auto& stages = plan.stages;
  ASSERT_EQ(stages.size(), 3u);
  ASSERT_TRUE(stages[0].controls);
  EXPECT_EQ(stages[0].controls->kind, ControlKind::kInitialRigidVelocity);
  EXPECT_EQ(stages[0].controls->alpha, 0.5);
  ASSERT_TRUE(stages[1].controls);
  EXPECT_EQ(stages[1].controls->kind, ControlKind::kInitialLatticeVelocity);
  EXPECT_EQ(stages[0].max_evaluations + stages[1].max_evaluations + stages[2].max_evaluations, 90);
  EXPECT_FALSE(stages[2].controls);
  const Scene no_search =
      strategy_scene(kCloth, R"({"kind": "initial_velocity"})", R"({"max_evaluations": 90, "throw_search": 0})");
  EXPECT_EQ(plan_stages(no_search).throw_search, 0);
}

TEST(Strategy, AutomaticThrowSearchScalesWithTheSimulationsCost) {
  EXPECT_EQ(automatic_throw_count(144, 45), 512);       // a 12 x 12 towel over 1.5 s: the cap
  EXPECT_EQ(automatic_throw_count(2500, 56), 32);       // a 50 x 50 sheet: the floor
  EXPECT_EQ(automatic_throw_count(300, 40), 333);       // 4e6 particle-steps
  EXPECT_EQ(automatic_throw_count(676, 30), 69);        // a 26 x 26 sheet: 197 times (12000 / 20280)²
}

// The search returns the best throw it simulated: no throw it tried, re-simulated, does better, and the
// scene's own throw (zero controls) is among them.
TEST(ThrowSearch, StartsFromTheBestThrowItSimulated) {
  const Scene scene = strategy_scene(kCloth, R"({"kind": "initial_rigid_velocity"})", R"({"max_evaluations": 10})");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  const ThrowSearch found = search_throws(problem, 16);
  EXPECT_EQ(found.simulated, 16);
  EXPECT_LE(found.phi, found.start_phi);
  EXPECT_DOUBLE_EQ(problem.evaluate(found.z, nullptr), found.phi);
  EXPECT_DOUBLE_EQ(problem.evaluate(VecX::Zero(6), nullptr), found.start_phi);
  EXPECT_GT(found.speed, 0);
  EXPECT_GT(found.spin, 0);
  // The same throws on every run.
  EXPECT_EQ(search_throws(problem, 16).z, found.z);
}

TEST(Strategy, SingleFlocksAndSchedulesRunAsWritten) {
  EXPECT_EQ(plan_stages(strategy_scene(kCloth, R"({"kind": "per_frame"})", R"({"strategy": "single", "window_growth": 1})"))
                .stages.size(),
            1u);
  const Scene flock = strategy_scene(R"("flock": {"agents": 4, "spawn": {"radius": 3}})", R"({"kind": "per_frame"})");
  EXPECT_EQ(plan_stages(flock).stages.size(), 1u);
  const Scene scheduled = strategy_scene(kCloth, R"({"kind": "per_frame"})",
                                         R"({"schedule": [{"substeps": 1, "max_evaluations": 7}, {"substeps": 2}]})");
  const auto stages = plan_stages(scheduled).stages;
  ASSERT_EQ(stages.size(), 2u);
  EXPECT_EQ(stages[0].max_evaluations, 7);
  EXPECT_FALSE(stages[0].controls);
}

TEST(Strategy, BadKeysSayWhichAndWhy) {
  EXPECT_THROW(strategy_scene(kCloth, R"({"kind": "per_frame"})", R"({"strategy": "multiple"})"), InputError);
  EXPECT_THROW(strategy_scene(kCloth, R"({"kind": "per_frame"})", R"({"window_frames": 0})"), InputError);
  EXPECT_THROW(strategy_scene(kCloth, R"({"kind": "per_frame"})", R"({"first_step": -1})"), InputError);
  EXPECT_THROW(strategy_scene(kCloth, R"({"kind": "per_frame"})", R"({"window_growth": 0.5})"), InputError);
}

}  // namespace
}  // namespace kf

// Friction eased in by the strategy (opt/friction_continuation.h): the scene scaled, the plan's stages, the
// order they run in on their systems; and the rule that no run ends with a keyframe worse than uncontrolled
// (opt/uncontrolled_floor.h).
#include <gtest/gtest.h>

#include <numeric>
#include <string>
#include <vector>

#include "opt/friction_continuation.h"
#include "opt/problem.h"
#include "opt/strategy.h"
#include "opt/uncontrolled_floor.h"
#include "opt/windows.h"
#include "scene/scene.h"
#include "sim/make_system.h"
#include "toy_system.h"

namespace kf {
namespace {

// A 5 x 5 sheet dropped sliding onto the ground (friction `mu`), keyframes before and after it lands.
Scene sliding_sheet(double mu, int max_evaluations = 300) {
  const std::string m = std::to_string(mu);
  return parse_scene(R"({"time": {"fps": 30, "frames": 16},
    "cloth": {"nx": 5, "ny": 5, "width": 0.4, "height": 0.4, "origin": [0, 0.06, 0], "u_axis": [1, 0, 0],
              "v_axis": [0, 0, 1], "velocity": [1.0, 0, 0],
              "colliders": [{"type": "ground", "friction": )" + m + R"(},
                            {"type": "sphere", "center": [2, 0, 2], "radius": 0.1, "friction": )" + m + R"(}]},
    "objectives": [{"type": "center_of_mass", "frame": 6, "target": [0.35, 0.02, 0.2]},
                   {"type": "center_of_mass", "frame": 16, "target": [0.6, 0.02, 0.25]}],
    "controls": {"kind": "per_frame"}, "optimizer": {"max_evaluations": )" + std::to_string(max_evaluations) + "}}",
                     "sliding.json");
}

TEST(FrictionContinuation, ScalesEveryCoefficientAndKeepsTheStickingSpeed) {
  Scene scene = sliding_sheet(0.4);
  scene.cloth->colliders[1].friction_velocity = 0.05;
  EXPECT_TRUE(has_friction(scene));
  const Scene half = with_friction_scaled(scene, 0.5);
  EXPECT_DOUBLE_EQ(half.cloth->colliders[0].friction, 0.2);
  EXPECT_DOUBLE_EQ(half.cloth->colliders[1].friction, 0.2);
  EXPECT_DOUBLE_EQ(half.cloth->colliders[1].friction_velocity, 0.05);
  EXPECT_FALSE(has_friction(with_friction_scaled(scene, 0)));
  EXPECT_FALSE(has_friction(sliding_sheet(0)));
  Scene self = sliding_sheet(0);
  self.cloth->self.enabled = true;
  self.cloth->self.friction = 0.3;
  EXPECT_TRUE(has_friction(self));
  EXPECT_FALSE(has_friction(with_friction_scaled(self, 0)));
}

// Per-frame forces on a sheet meeting colliders get windows; eased friction plans them twice: eased first on a
// share of the budget, then at the scene's friction, the whole budget shared between them. plan_stages itself
// plans them once, and a scene without friction, or a scale of 1, is left as it is.
TEST(FrictionContinuation, PlansTheWindowsEasedThenAtTheScenesFriction) {
  const StagePlan plain = plan_stages(sliding_sheet(0));
  ASSERT_GT(plain.stages.size(), 1u);
  EXPECT_TRUE(plain.friction_scales.empty());
  StagePlan plan = plan_stages(sliding_sheet(0.4));
  EXPECT_EQ(plan.stages.size(), plain.stages.size());
  EXPECT_TRUE(plan.friction_scales.empty());
  StagePlan untouched = plain;
  ease_friction(sliding_sheet(0), 0, untouched);
  EXPECT_TRUE(untouched.friction_scales.empty());
  ease_friction(sliding_sheet(0.4), 1, plan);
  EXPECT_TRUE(plan.friction_scales.empty());
  ease_friction(sliding_sheet(0.4), 0, plan);
  ASSERT_EQ(plan.stages.size(), 2 * plain.stages.size()) << plan.why;
  ASSERT_EQ(plan.friction_scales.size(), plan.stages.size());
  ASSERT_EQ(plan.judged_until.size(), plan.stages.size());
  const size_t n = plain.stages.size();
  int budget = 0;
  for (size_t s = 0; s < plan.stages.size(); ++s) {
    EXPECT_EQ(plan.friction_scales[s], s < n ? 0.0 : 1.0) << s;
    EXPECT_EQ(plan.judged_until[s], plan.judged_until[s % n]) << s;
    EXPECT_EQ(plan.stages[s].controls.has_value(), plain.stages[s % n].controls.has_value()) << s;
    budget += plan.stages[s].max_evaluations;
  }
  EXPECT_EQ(budget, 300);
  EXPECT_LT(plan.stages[0].max_evaluations, plain.stages[0].max_evaluations);
  EXPECT_NE(plan.why.find("friction eased in"), std::string::npos) << plan.why;
}

struct CountingLog final : StrategyLog {
  std::vector<std::string> lines;
  void say(const std::string& line) override { lines.push_back(line); }
  void evaluation(int, int, double, const EvaluationRecord&) override {}
};

// φ at no force, with the keyframes after frame `until` left out (a window's, opt/windows.h).
double phi_at_start(const Scene& scene, int until) {
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  std::vector<double> scales;
  for (const auto& o : scene.objectives) scales.push_back(until == kAllKeyframes || o.frame <= until ? 1.0 : 0.0);
  problem.set_weight_scales(scales);
  return problem.evaluate(problem.initial_guess(), nullptr);
}

// The eased stages simulate the scene without friction (their first evaluation is the frictionless scene's
// objective at no force) on systems the strategy builds; the later ones come from the hooks, at the scene's.
TEST(FrictionContinuation, EasedStagesRunFirstWithoutFrictionThenTheScenesFromTheirControls) {
  const Scene scene = sliding_sheet(0.4, 48);
  StagePlan plan = plan_stages(scene);
  ease_friction(scene, 0, plan);
  const size_t n = plan.stages.size() / 2;
  ASSERT_GE(n, 2u);
  int hooked = 0;
  StrategyHooks hooks;
  hooks.make_system = [&](double h) {
    ++hooked;
    return make_system(scene, h);
  };
  StrategySetup setup{scene, plan};
  setup.system = make_system(scene);
  setup.start_time = scene.time;
  CountingLog log;
  const StrategyResult r = run_strategy(std::move(setup), hooks, log);
  ASSERT_EQ(r.stages.size(), plan.stages.size());
  EXPECT_EQ(hooked, int(n));  // every stage at the scene's friction, none of the eased ones
  const int until = plan.judged_until[0];
  const double frictionless = phi_at_start(with_friction_scaled(scene, 0), until);
  ASSERT_NE(frictionless, phi_at_start(scene, until)) << "friction changes nothing in this scene";
  EXPECT_DOUBLE_EQ(r.stages[0].objective_start, frictionless);
  // The first stage at the scene's friction starts from the eased stages' forces, not from none.
  EXPECT_NE(r.stages[n].objective_start, phi_at_start(scene, until));
  EXPECT_LT(r.stages.back().objective_end, phi_at_start(scene, kAllKeyframes));
}

// The toy chain (linear: a uniform force moves its centre of mass along itself) with keyframes at frames 28
// and 12; only the one at frame 12 is judged (the other counts as met).
struct FloorToy {
  Scene scene = parse_scene(R"({"time": {"fps": 30, "substeps": 2, "frames": 30}, "cloth": {"nx": 2, "ny": 2},
    "objectives": [{"type": "center_of_mass", "frame": 28, "target": [0.3, 0.1, 0.2]},
                   {"type": "center_of_mass", "frame": 12, "target": [0.1, 0.1, 0.1]}],
    "controls": {"kind": "per_frame"}})",
                            "floor.json");
  test::ToySystem sys{4, scene.time.h()};
  Problem problem{scene, scene.time, sys};
  VecX z0 = problem.initial_guess(), toward, away;  // controls moving keyframe 12 toward or away from its target
  std::function<std::vector<bool>(Problem&)> unmet = [](Problem& p) {
    return std::vector<bool>{false, p.breakdown()[1].second > 1e-12};
  };
  FloorToy() {
    VecX g(problem.size());
    problem.set_weight_scales({0, 1});
    problem.evaluate(z0, &g);
    problem.set_weight_scales({});
    toward = z0 - 0.05 * g / g.norm();
    away = z0 + 0.05 * g / g.norm();
  }
  double term12(const VecX& z) {
    problem.evaluate(z, nullptr);
    return problem.breakdown()[1].second;
  }
};

TEST(UncontrolledFloor, AResultFartherThanUncontrolledFallsBackToTheBestStageEndOrToNoControl) {
  FloorToy t;
  const double none = t.term12(t.z0);
  ASSERT_LT(t.term12(t.toward), none);
  ASSERT_GT(t.term12(t.away), none);
  // A result no farther off is kept.
  EXPECT_FALSE(uncontrolled_floor(t.problem, {t.toward, t.away}, t.unmet).fell_back());
  // One farther off gives way to the stage end that is not, and the problem is left evaluated there.
  const FloorVerdict v = uncontrolled_floor(t.problem, {t.away, 2 * t.away, t.toward}, t.unmet);
  EXPECT_EQ(v.chosen, 2u);
  EXPECT_NE(v.why.find("center_of_mass@12"), std::string::npos) << v.why;
  EXPECT_DOUBLE_EQ(t.problem.breakdown()[1].second, t.term12(t.toward));
  // With none that is not, to no control.
  const FloorVerdict none_left = uncontrolled_floor(t.problem, {t.away, 2 * t.away}, t.unmet);
  EXPECT_EQ(none_left.chosen, 2u);
  EXPECT_NE(none_left.why.find("no control"), std::string::npos) << none_left.why;
  EXPECT_DOUBLE_EQ(t.problem.breakdown()[1].second, none);
}

// The toy chain's uncontrolled centre of mass at `frame` (equal masses).
Vec3 toy_center_at(int frame, int substeps, double h) {
  test::ToySystem sys(4, h);
  VecX x, v, x1(12), v1(12), u = VecX::Zero(12);
  sys.initial_state(x, v);
  StepRecord record;
  for (int n = 0; n < frame * substeps; ++n) {
    sys.step(n, x, v, u, x1, v1, record);
    x = x1;
    v = v1;
  }
  Vec3 c = Vec3::Zero();
  for (int i = 0; i < 4; ++i) c += x.segment<3>(3 * i) / 4;
  return c;
}

// Through the strategy: the keyframe at frame 12 sits where the chain is uncontrolled, so a stage pulling the
// one at frame 28 away (weight 1e3) leaves it farther off than no control; the run ends at no control.
TEST(UncontrolledFloor, TheStrategyKeepsNoControlOverAResultThatMadeAKeyframeWorse) {
  Scene scene = parse_scene(R"({"time": {"fps": 30, "substeps": 2, "frames": 30}, "cloth": {"nx": 2, "ny": 2},
    "objectives": [{"type": "center_of_mass", "frame": 28, "target": [2, 1, 0.5], "weight": 1e3},
                   {"type": "center_of_mass", "frame": 12, "target": [0, 0, 0]}],
    "controls": {"kind": "per_frame"},
    "optimizer": {"max_evaluations": 20, "split_schedule": "adaptive", "soft_keyframes": true}})",
                            "floor-run.json");
  std::get<CenterOfMassKeyframe>(scene.objectives[1].kind).target =
      toy_center_at(12, scene.time.substeps, scene.time.h());
  const auto unmet = [](Problem& p) { return std::vector<bool>{false, p.breakdown()[1].second > 1e-12}; };
  const auto run = [&](bool floor) {
    StagePlan plan;
    plan.stages = {{scene.time.substeps, 20, std::nullopt}};
    StrategyHooks hooks;
    hooks.make_system = [](double h) { return std::make_unique<test::ToySystem>(4, h); };
    if (floor) hooks.keyframes_unmet = unmet;
    StrategySetup setup{scene, plan};
    setup.system = hooks.make_system(scene.time.h());
    setup.start_time = scene.time;
    CountingLog log;
    StrategyResult r = run_strategy(std::move(setup), hooks, log);
    bool said = false;
    for (const auto& l : log.lines) said |= l.find("center_of_mass@12 farther off than uncontrolled") != std::string::npos;
    return std::make_pair(std::move(r), said);
  };
  const auto [without, said_without] = run(false);
  ASSERT_EQ(without.stages.size(), 1u);
  EXPECT_LT(without.stages[0].objective_end, without.stages[0].objective_start);
  without.problem->evaluate(without.problem->initial_guess(), nullptr);
  ASSERT_LT(without.problem->breakdown()[1].second, 1e-20) << "the target is not the uncontrolled centre";
  without.problem->evaluate(without.z, nullptr);
  ASSERT_GT(without.problem->breakdown()[1].second, 1e-12) << "the stage left frame 12 where it was";
  EXPECT_FALSE(said_without);
  const auto [with, said] = run(true);
  EXPECT_TRUE(said);
  EXPECT_EQ(with.z, with.problem->initial_guess());
  EXPECT_LT(with.problem->breakdown()[1].second, 1e-20);  // left evaluated at the controls it ends with
}

}  // namespace
}  // namespace kf

// The strategy (opt/strategy.h) run on a toy chain (tests/opt/toy_system.h: no cloth, no flock) through its
// hooks and log: the order of its stages, evaluations passed on between them, restarts after a stalled line
// search, the stop rule, an interruption, and the windows after a single stage that ended early.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <string>
#include <vector>

#include "opt/strategy.h"
#include "scene/scene.h"
#include "toy_system.h"

namespace kf {
namespace {

Scene toy_scene(const std::string& optimizer = "{}", const std::string& controls = R"({"kind": "per_frame"})") {
  return parse_scene(R"({"time": {"fps": 30, "substeps": 2, "frames": 30}, "cloth": {"nx": 2, "ny": 2},
    "objectives": [{"type": "center_of_mass", "frame": 28, "target": [0.3, 0.1, 0.2], "weight": 1e3},
                   {"type": "center_of_mass", "frame": 12, "target": [0.1, 0.1, 0.1]}],
    "controls": )" + controls + R"(, "optimizer": )" + optimizer + "}",
                     "strategy_run.json");
}

// A toy chain whose adjoint gives the negated control gradient: no direction L-BFGS takes from it descends,
// so its line search stalls.
class WrongGradientToy final : public test::ToySystem {
 public:
  using ToySystem::ToySystem;
  using System::step_adjoint;
  void step_adjoint(int n, const VecX& x, const VecX& v, const VecX& u, const StepRecord& r, const VecX& xhat1,
                    const VecX& vhat1, VecX& xhat, VecX& vhat, VecX& uhat) override {
    ToySystem::step_adjoint(n, x, v, u, r, xhat1, vhat1, xhat, vhat, uhat);
    uhat = -uhat;
  }
};

struct ToyLog final : StrategyLog {
  std::vector<std::string> lines;
  std::vector<int> stage_of_evaluation, substeps_of_evaluation, budgets;
  std::atomic<bool>* stop = nullptr;  // set after `stop_after` evaluations, as a signal would
  size_t stop_after = 0;
  void say(const std::string& line) override { lines.push_back(line); }
  void evaluation(int stage_id, int substeps, double, const EvaluationRecord&) override {
    stage_of_evaluation.push_back(stage_id);
    substeps_of_evaluation.push_back(substeps);
    if (stop && stage_of_evaluation.size() == stop_after) *stop = true;
  }
  void stage_started(int max_evaluations) override { budgets.push_back(max_evaluations); }
  int said(const std::string& start) const {
    int n = 0;
    for (const auto& l : lines) n += l.rfind(start, 0) == 0;
    return n;
  }
};

struct ToyRun {
  StrategyResult result;
  ToyLog log;
};

ToyRun run_toy(const Scene& scene, const StagePlan& plan, bool wrong_gradient = false,
               std::function<bool(Problem&)> met = {}, std::atomic<bool>* stop = nullptr, size_t stop_after = 0) {
  const auto make = [wrong_gradient](double h) -> std::unique_ptr<System> {
    if (wrong_gradient) return std::make_unique<WrongGradientToy>(4, h);
    return std::make_unique<test::ToySystem>(4, h);
  };
  StrategyHooks hooks;
  hooks.make_system = make;
  hooks.keyframes_met = std::move(met);
  StrategySetup setup{scene, plan};
  TimeSpec first = scene.time;
  first.substeps = plan.stages[0].substeps;
  setup.system = make(first.h());
  setup.start_time = scene.time;
  setup.stop = stop;
  ToyRun run;
  run.log.stop = stop;
  run.log.stop_after = stop_after;
  run.result = run_strategy(std::move(setup), hooks, run.log);
  return run;
}

StagePlan plan_of(std::vector<StageSpec> stages) {
  StagePlan plan;
  plan.stages = std::move(stages);
  return plan;
}

TEST(StrategyRun, StagesRunInOrderAndPassTheirUnspentEvaluationsOn) {
  // A loose ftol_rel: the first stage converges well inside its 60 evaluations.
  const Scene scene = toy_scene(R"({"ftol_rel": 1e-3, "split_schedule": "adaptive"})");
  const ToyRun run = run_toy(scene, plan_of({{1, 60, std::nullopt}, {2, 7, std::nullopt}, {2, 5, std::nullopt}}));
  const StrategyResult& r = run.result;
  ASSERT_EQ(r.stages.size(), 3u);
  EXPECT_EQ(r.planned_stages, 3);
  ASSERT_LT(r.stages[0].evaluations, 60);
  EXPECT_EQ(r.stages[0].reason, StopReason::kConverged);
  // Each stage's budget is its own plus what the one before left.
  ASSERT_EQ(run.log.budgets.size(), 3u);
  EXPECT_EQ(run.log.budgets[0], 60);
  EXPECT_EQ(run.log.budgets[1], 7 + 60 - r.stages[0].evaluations);
  EXPECT_EQ(run.log.budgets[2], 5 + run.log.budgets[1] - r.stages[1].evaluations);
  // Evaluations come stage after stage, each at its stage's substeps, and the result is the last stage's.
  std::vector<int> expected_stage, expected_substeps;
  for (int s = 0; s < 3; ++s)
    for (int k = 0; k < r.stages[s].evaluations; ++k) {
      expected_stage.push_back(s + 1);
      expected_substeps.push_back(s == 0 ? 1 : 2);
    }
  EXPECT_EQ(run.log.stage_of_evaluation, expected_stage);
  EXPECT_EQ(run.log.substeps_of_evaluation, expected_substeps);
  EXPECT_EQ(r.time.substeps, 2);
  EXPECT_EQ(r.evaluations, r.stages[0].evaluations + r.stages[1].evaluations + r.stages[2].evaluations);
  // Each stage starts from the controls the last one found: at the same substeps, where the last one ended.
  EXPECT_DOUBLE_EQ(r.stages[2].objective_start, r.stages[1].objective_end);
  EXPECT_LT(r.stages[0].objective_end, r.stages[0].objective_start);
  EXPECT_EQ(r.tape.records().size(), size_t(r.evaluations));
}

TEST(StrategyRun, FixedBudgetsPassNothingOn) {
  const Scene scene = toy_scene(R"({"ftol_rel": 1e-3, "split_schedule": "adaptive"})");
  StagePlan plan = plan_of({{1, 60, std::nullopt}, {2, 7, std::nullopt}});
  StrategyHooks hooks;
  hooks.make_system = [](double h) { return std::make_unique<test::ToySystem>(4, h); };
  StrategySetup setup{scene, plan};
  TimeSpec first = scene.time;
  first.substeps = 1;
  setup.system = hooks.make_system(first.h());
  setup.fixed_budgets = true;
  ToyLog log;
  const StrategyResult r = run_strategy(std::move(setup), hooks, log);
  ASSERT_EQ(log.budgets.size(), 2u);
  EXPECT_LT(r.stages[0].evaluations, 60);
  EXPECT_EQ(log.budgets[1], 7);
}

TEST(StrategyRun, AStalledLineSearchRestartsFromTheBestPointWithWhatIsLeft) {
  const Scene scene = toy_scene(R"({"split_schedule": "adaptive", "restarts": 3})");
  const ToyRun run = run_toy(scene, plan_of({{2, 40, std::nullopt}}), /*wrong_gradient=*/true);
  const StrategyResult& r = run.result;
  ASSERT_EQ(r.stages.size(), 1u);
  EXPECT_EQ(r.reason, StopReason::kLineSearchStalled) << r.status;
  EXPECT_EQ(r.status.rfind("stopped: line search", 0), 0u) << r.status;
  // The first start stalled, one restart was made and, making no progress, was the last.
  EXPECT_EQ(run.log.said("restart 1 from objective"), 1);
  EXPECT_EQ(run.log.said("restart 2"), 0);
  EXPECT_LE(r.evaluations, 40);
  // The restart's evaluations are numbered on from the first start's.
  ASSERT_EQ(run.log.stage_of_evaluation.size(), size_t(r.evaluations));
  // No step descended: the best point is the start.
  EXPECT_DOUBLE_EQ(r.stages[0].objective_end, r.stages[0].objective_start);
}

TEST(StrategyRun, NoRestartsWhenNoneAreAllowed) {
  const Scene scene = toy_scene(R"({"split_schedule": "adaptive", "restarts": 0})");
  const ToyRun run = run_toy(scene, plan_of({{2, 40, std::nullopt}}), /*wrong_gradient=*/true);
  EXPECT_EQ(run.result.reason, StopReason::kLineSearchStalled);
  EXPECT_EQ(run.log.said("restart"), 0);
}

TEST(StrategyRun, ReachedKeyframesEndTheRunBeforeItsLaterStages) {
  const Scene scene = toy_scene(R"({"split_schedule": "adaptive", "stop_when_reached": true})");
  int asked = 0;
  const auto met = [&asked](Problem& p) {
    EXPECT_FALSE(p.last_diverged());
    return ++asked == 3;  // the third improvement on the best point meets every keyframe
  };
  const ToyRun run = run_toy(scene, plan_of({{2, 30, std::nullopt}, {2, 30, std::nullopt}}), false, met);
  const StrategyResult& r = run.result;
  EXPECT_EQ(asked, 3);
  ASSERT_EQ(r.stages.size(), 1u);
  EXPECT_EQ(r.reason, StopReason::kKeyframesReached);
  EXPECT_EQ(r.stages[0].reason, StopReason::kKeyframesReached);
  EXPECT_LT(r.evaluations, 30);
}

TEST(StrategyRun, WithoutStopWhenReachedTheRuleIsNotAsked) {
  const Scene scene = toy_scene(R"({"split_schedule": "adaptive", "stop_when_reached": false})");
  int asked = 0;
  const ToyRun run = run_toy(scene, plan_of({{2, 10, std::nullopt}}), false, [&asked](Problem&) { return ++asked > 0; });
  EXPECT_EQ(asked, 0);
  EXPECT_NE(run.result.reason, StopReason::kKeyframesReached);
}

TEST(StrategyRun, AStopRequestEndsTheRunInItsStage) {
  const Scene scene = toy_scene(R"({"split_schedule": "adaptive"})");
  std::atomic<bool> stop{false};
  const ToyRun run = run_toy(scene, plan_of({{2, 30, std::nullopt}, {2, 30, std::nullopt}}), false, {}, &stop, 4);
  ASSERT_EQ(run.result.stages.size(), 1u);
  EXPECT_TRUE(run.result.interrupted);
  EXPECT_EQ(run.result.reason, StopReason::kInterrupted);
  EXPECT_EQ(run.result.evaluations, 4);  // the evaluation asked for after the request is not made
}

TEST(StrategyRun, AStopRequestBeforeTheFirstEvaluationRecordsNoStage) {
  const Scene scene = toy_scene(R"({"split_schedule": "adaptive"})");
  std::atomic<bool> stop{true};
  const ToyRun run = run_toy(scene, plan_of({{2, 30, std::nullopt}, {2, 30, std::nullopt}}), false, {}, &stop);
  EXPECT_TRUE(run.result.stages.empty());
  EXPECT_TRUE(run.result.interrupted);
  EXPECT_EQ(run.result.reason, StopReason::kInterrupted);
  EXPECT_EQ(run.result.evaluations, 0);
  EXPECT_TRUE(run.log.stage_of_evaluation.empty());
}

TEST(StrategyRun, ASingleStageThatEndedEarlyIsFollowedByWindows) {
  // Forces from frame 0 with the last keyframe at frame 28: windows of 5, 10 and 20 frames back from it, then
  // the whole horizon.
  const Scene scene = toy_scene(R"({"ftol_rel": 1e-3, "split_schedule": "adaptive", "max_evaluations": 200})");
  StagePlan plan = plan_of({{2, 200, std::nullopt}});
  plan.windows_on_early_end = true;
  const ToyRun run = run_toy(scene, plan);
  const StrategyResult& r = run.result;
  ASSERT_GE(r.stages.size(), 2u);
  EXPECT_EQ(r.stages[0].reason, StopReason::kConverged);
  EXPECT_EQ(run.log.said("the one stage ended (converged"), 1);
  const std::vector<StageSpec> windows = window_stages(scene, 200 - r.stages[0].evaluations);
  EXPECT_EQ(r.planned_stages, 1 + int(windows.size()));
  // The windows start from no force over the shortest window before the earlier keyframe (frame 12), on the
  // lattice.
  EXPECT_EQ(run.log.said("optimising strategy_run stage 2"), 1);
  ASSERT_EQ(run.log.said("optimising strategy_run stage 2: toy chain"), 1);
  for (const auto& line : run.log.lines)
    if (line.rfind("optimising strategy_run stage 2", 0) == 0) EXPECT_NE(line.find("(per_frame_lattice from frame 7)"), std::string::npos) << line;
  // The result is the better of the single stage and the windows.
  const bool windows_kept = r.stages.back().objective_end < r.stages[0].objective_end;
  EXPECT_EQ(run.log.said("the windows ended no lower"), windows_kept ? 0 : 1);
}

// The toy's centre of mass at `frame` of the problem's last rollout, and its distance to `target`.
double com_miss(const Problem& p, int frame, const Vec3& target) {
  const VecX& x = p.rollout().x[size_t(frame * p.time().substeps)];
  Vec3 c = Vec3::Zero();
  for (long i = 0; i < x.size() / 3; ++i) c += x.segment<3>(3 * i);
  return (c / double(x.size() / 3) - target).norm();
}

TEST(StrategyRun, KeyframesAtSeveralFramesAreSteeredInTimeOrder) {
  // Keyframes at frames 12 and 28, per-step forces from frame 0, windows of 5 frames: first the windows
  // grown back from frame 12 (only that keyframe counts), then those grown back from frame 28 down to 12
  // (both count; the forces before the window held), then the whole horizon.
  const Scene scene =
      toy_scene(R"({"split_schedule": "adaptive", "stop_when_reached": true, "window_frames": 5})", R"({"kind": "per_step"})");
  StagePlan plan;
  plan.stages = window_stages(scene, 240, &plan.judged_until);
  std::vector<int> starts;
  for (const auto& st : plan.stages) starts.push_back(st.controls ? st.controls->from_frame : -1);
  EXPECT_EQ(starts, (std::vector<int>{7, 2, 0, 23, 18, 12, -1}));
  EXPECT_EQ(plan.judged_until, (std::vector<int>{12, 12, 12, kAllKeyframes, kAllKeyframes, kAllKeyframes, kAllKeyframes}));
  // Each keyframe's first window shares half the budget.
  EXPECT_EQ(plan.stages[0].max_evaluations, 60);
  EXPECT_EQ(plan.stages[3].max_evaluations, 60);
  const Vec3 early(0.1, 0.1, 0.1), late(0.3, 0.1, 0.2);
  constexpr double kTolerance = 0.05;
  std::vector<double> early_miss_in_late_windows;
  const auto unmet = [&](Problem& p) {
    const double e = com_miss(p, 12, early), l = com_miss(p, 28, late);
    if (p.controls().first_frame() > 12) early_miss_in_late_windows.push_back(e);
    return std::vector<bool>{l > kTolerance, e > kTolerance};  // scene.objectives order
  };
  StrategyHooks hooks;
  hooks.make_system = [](double h) { return std::make_unique<test::ToySystem>(4, h); };
  hooks.keyframes_unmet = unmet;
  hooks.keyframes_met = [&](Problem& p) {
    const std::vector<bool> u = unmet(p);
    return !u[0] && !u[1];
  };
  StrategySetup setup{scene, plan};
  setup.system = hooks.make_system(scene.time.h());
  ToyLog log;
  StrategyResult r = run_strategy(std::move(setup), hooks, log);
  // The early keyframe was met in its own windows, and the run went on to the later one.
  EXPECT_EQ(log.said("the keyframes up to frame 12 are met: on to the next keyframe"), 1);
  std::vector<int> from;
  for (const auto& line : log.lines)
    if (line.rfind("optimising strategy_run stage", 0) == 0) {
      const size_t at = line.find("from frame ");
      from.push_back(at == std::string::npos ? 0 : std::stoi(line.substr(at + 11)));
    }
  // First windows before frame 12, then the rest of the early keyframe's windows skipped (three planned).
  const size_t first_late = size_t(std::find_if(from.begin(), from.end(), [](int f) { return f > 12; }) - from.begin());
  ASSERT_LT(first_late, from.size());
  EXPECT_GE(first_late, 1u);
  EXPECT_LT(first_late, 3u);
  for (size_t k = first_late; k + 1 < from.size(); ++k) EXPECT_GE(from[k], 12) << "stage " << k + 1;
  // While a window after frame 12 was optimised, the forces before it were held: the early keyframe stayed met.
  ASSERT_FALSE(early_miss_in_late_windows.empty());
  for (double e : early_miss_in_late_windows) EXPECT_LE(e, kTolerance);
  EXPECT_EQ(r.reason, StopReason::kKeyframesReached) << r.status;
  r.problem->evaluate(r.z, nullptr);
  EXPECT_LE(com_miss(*r.problem, 28, late), kTolerance);
  EXPECT_LE(com_miss(*r.problem, 12, early), kTolerance);
}

// Per-frame forces: each keyframe's lattice windows, then a per-particle window over its first window's
// frames, then the whole horizon per particle. Each per-particle stage starts where the stage before it
// ended (the lattice forces spread over the particles, those before the window held): without an effort
// term the keyframe terms alone are φ, so its first φ is the last stage's best.
TEST(StrategyRun, PerParticleWindowsStartWhereTheLatticeWindowsEnded) {
  const Scene scene = toy_scene(R"({"split_schedule": "adaptive", "stop_when_reached": false, "window_frames": 5})",
                                R"({"kind": "per_frame", "alpha": 0})");
  StagePlan plan;
  plan.stages = window_stages(scene, 240, &plan.judged_until);
  std::vector<int> starts;
  for (const auto& st : plan.stages) starts.push_back(st.controls ? st.controls->from_frame : -1);
  ASSERT_EQ(starts, (std::vector<int>{7, 2, 0, 7, 23, 18, 12, 23, -1}));
  const ToyRun run = run_toy(scene, plan);
  const StrategyResult& r = run.result;
  ASSERT_EQ(r.stages.size(), plan.stages.size());
  for (size_t s : {size_t(3), size_t(7), size_t(8)}) {
    EXPECT_EQ(r.stages[s].kind, ControlKind::kPerFrame) << "stage " << s;
    EXPECT_EQ(r.stages[s - 1].kind, s == 8 ? ControlKind::kPerFrame : ControlKind::kPerFrameLattice) << "stage " << s;
    EXPECT_GT(r.stages[s - 1].objective_end, 0) << "stage " << s;
    EXPECT_NEAR(r.stages[s].objective_start, r.stages[s - 1].objective_end, 1e-9 * r.stages[s - 1].objective_end)
        << "stage " << s;
    EXPECT_LE(r.stages[s].objective_end, r.stages[s].objective_start) << "stage " << s;
  }
}

}  // namespace
}  // namespace kf

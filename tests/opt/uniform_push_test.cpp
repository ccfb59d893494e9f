// The uniform push (opt/uniform_push.h): one acceleration on every particle, fitted by Levenberg–Marquardt to
// the keyframes. A generated gravity-tilt scene's variant is exactly such a push (m_i Δg at every step).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <iostream>
#include <sstream>

#include "bench/bench_reachable.h"
#include "opt/keyframe_residuals.h"
#include "opt/keyframes/keyframe_common.h"
#include "opt/problem.h"
#include "opt/strategy.h"
#include "opt/throw_search.h"
#include "opt/uniform_push.h"
#include "scene/scene.h"
#include "sim/make_system.h"

namespace kf {
namespace {

// The keyframe terms of the problem's last evaluation (every term but the effort, the last).
double keyframe_terms(const Problem& problem) {
  double sum = 0;
  const auto& terms = problem.breakdown();
  for (size_t k = 0; k + 1 < terms.size(); ++k) sum += terms[k].second;
  return sum;
}

// The worst placed keyframe's distance under the problem's last rollout, in tolerances.
double worst_miss(Problem& problem, const Scene& scene) {
  const std::vector<PlacedKeyframe> placed = placed_keyframes(problem, scene);
  VecX r(residual_count(placed));
  const double worst = keyframe_residuals(problem.rollout(), placed, false, r);
  return worst / cloth_tolerance(scene);
}

double cpu_seconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

// Per-particle forces, per frame and per step, from a later frame: every controlled step gets m_i a exactly,
// the steps before none.
TEST(UniformPush, ControlsGiveEveryParticleItsMassTimesThePush) {
  for (const char* kind : {"per_frame", "per_step"}) {
    SCOPED_TRACE(kind);
    const Scene scene = parse_scene(std::string(R"({"time": {"fps": 30, "substeps": 3, "frames": 6},
        "cloth": {"nx": 4, "ny": 3, "width": 0.3, "height": 0.2, "mass": 0.1, "pins": [0]},
        "objectives": [{"type": "center_of_mass", "frame": 6, "target": [0, 0, 0]}],
        "controls": {"kind": ")") + kind + R"(", "from_frame": 2}})", "push.json");
    auto sys = make_system(scene);
    Problem problem(scene, scene.time, *sys);
    const Vec3 a(0.5, -2.0, 1.5);
    const VecX z = uniform_push_controls(problem, a);
    ASSERT_EQ(z.size(), problem.size());
    VecX u;
    for (int n = 0; n < scene.time.steps(); ++n) {
      problem.force_at(z, n, u);
      for (int i = 0; i < sys->particles(); ++i) {
        const Vec3 want = n < problem.controls().first_step() ? Vec3::Zero() : Vec3(sys->masses()[i] * a);
        EXPECT_LT((u.segment<3>(3 * i) - want).norm(), 1e-12) << "step " << n << " particle " << i;
      }
    }
  }
}

// Reduced generated gravity tilts (8 x 8, 15 frames; hanging, dropped on the ground): the fit from no push meets
// every keyframe. (Reduced drop-collider-2, dropped on a collider, stalls 9 tolerances off, and hang-points-0
// 1.39: tests/results/reachable/uniform/README section.)
TEST(UniformPush, ReducedGeneratedTiltsAreMetFromNoPush) {
  for (const auto& [kind, index] : {std::pair<const char*, int>{"hang-corners", 0}, {"hang-edge", 1}, {"drop-ground", 0}}) {
    const ReachableScene r = generate_reachable(kind, 52, index, true, ".");
    SCOPED_TRACE(r.name);
    const Scene scene = parse_scene(r.scene.dump(), r.name + ".json");
    auto sys = make_system(scene);
    Problem problem(scene, scene.time, *sys);
    FewFitOptions o;
    o.max_step = 5;
    const UniformPush push = fit_uniform_push(problem, scene, o);
    ASSERT_EQ(push.z.size(), problem.size()) << describe(push);
    EXPECT_EQ(push.stop, FitStop::kReached) << describe(push);
    EXPECT_LT(push.worst_miss, 0.01);
    EXPECT_LT(push.simulated, 60);
    // A curtain's keyframes say less of the push along its pins (Δg to a tenth); a rug on the ground's nothing
    // of the push into it.
    if (r.kind.rfind("hang", 0) == 0)
      EXPECT_LT((push.a - r.variant.dg).norm(), 0.1 * r.variant.dg.norm()) << push.a.transpose() << " vs "
                                                                        << r.variant.dg.transpose();
  }
}

// The ½|g| ball and the paying test end a fit early. With the ball at a third of the push the keyframes ask
// for, the fit's first step would leave it: it stops there, after its first Jacobian, at no push; with a paying
// share no fit can meet, it stops after the steps it was given, at the best point reached.
TEST(UniformPush, TheBallAndThePayingTestEndAFitEarly) {
  const ReachableScene r = generate_reachable("hang-corners", 52, 0, true, ".");
  const Scene scene = parse_scene(r.scene.dump(), r.name + ".json");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  FewFitOptions o;
  o.max_step = 5;
  o.max_norm = r.variant.dg.norm() / 3;
  UniformPush push = fit_uniform_push(problem, scene, o);
  EXPECT_EQ(push.stop, FitStop::kBounded) << describe(push);
  EXPECT_EQ(push.a.norm(), 0.0);
  EXPECT_EQ(push.simulated, 7) << describe(push);  // the start and one Jacobian's six
  // A ball wide enough: the fit as without it.
  o.max_norm = 10 * r.variant.dg.norm();
  EXPECT_EQ(fit_uniform_push(problem, scene, o).stop, FitStop::kReached);
  o.max_norm = 0;
  o.paying_steps = 1;
  o.paying_share = 1e-30;
  push = fit_uniform_push(problem, scene, o);
  EXPECT_EQ(push.stop, FitStop::kNotPaying) << describe(push);
  ASSERT_EQ(push.costs.size(), 2u);
  EXPECT_LT(push.costs[1], push.costs[0]);
  EXPECT_EQ(push.cost, push.costs[1]);
  EXPECT_LE(push.simulated, 14) << describe(push);  // a Jacobian, a step or a few, no second Jacobian
}

struct Lines final : StrategyLog {
  std::vector<std::string> lines;
  std::vector<int> budgets;
  void say(const std::string& line) override { lines.push_back(line); }
  void evaluation(int, int, double, const EvaluationRecord&) override {}
  void stage_started(int max_evaluations) override { budgets.push_back(max_evaluations); }
};

// A window from the scene's middle frame (`first` evaluations), then the whole horizon (10): run by the strategy.
StrategyResult run_half_window_plan(const Scene& scene, int first, bool push, Lines& log) {
  ControlSpec window = scene.controls;
  window.from_frame = scene.time.frames / 2;
  StagePlan plan;
  plan.stages = {{scene.time.substeps, first, window}, {scene.time.substeps, 10, std::nullopt}};
  plan.uniform_push = push;
  StrategyHooks hooks;
  hooks.make_system = [&scene](double h) { return make_system(scene, h); };
  StrategySetup setup{scene, plan};
  setup.system = make_system(scene);
  setup.start_time = scene.time;
  return run_strategy(std::move(setup), hooks, log);
}

// The strategy with a plan that asks for it: the first stage (here a window from a later frame) starts from the
// push, the forces before its window held, and the push's flights come off the last stage's budget.
TEST(UniformPush, TheFirstStageStartsFromThePushAndPaysForItsFlights) {
  const ReachableScene r = generate_reachable("hang-corners", 52, 0, true, ".");
  const Scene scene = parse_scene(r.scene.dump(), r.name + ".json");
  for (const bool push : {false, true}) {
    SCOPED_TRACE(push);
    Lines log;
    const StrategyResult res = run_half_window_plan(scene, 40, push, log);
    ASSERT_FALSE(res.stages.empty());
    ASSERT_EQ(res.uniform_push.has_value(), push);
    if (!push) {
      EXPECT_EQ(log.budgets.front(), 40);
      continue;
    }
    const UniformPush& p = *res.uniform_push;
    EXPECT_EQ(p.stop, FitStop::kReached) << describe(p);
    // The first window keeps its share; the last stage pays half an evaluation a flight.
    EXPECT_EQ(log.budgets.front(), 40);
    ASSERT_EQ(log.budgets.size(), 2u);
    EXPECT_EQ(log.budgets[1], std::max(1, 10 - (p.simulated + 1) / 2) + 40 - res.stages.front().evaluations);
    // The window starts where the push left the keyframes: its start's objective is the push's cost plus its
    // effort inside the window, far below no push's.
    EXPECT_LT(res.stages.front().objective_start, 1e-2 * p.start_cost);
    EXPECT_EQ(std::count_if(log.lines.begin(), log.lines.end(),
                            [](const std::string& l) { return l.rfind("uniform push:", 0) == 0; }),
              1);
  }
}

// A push that is not kept leaves the run as without it: a sheet under a tenth of its gravity, whose keyframes
// (fallen under all of it) ask for a push past half of its gravity, stops at the ball's edge; the stages'
// budgets, evaluations and objectives are those of the run without the push, and its flights are reported.
TEST(UniformPush, APushNotKeptLeavesTheRunAsWithoutIt) {
  const ReachableScene r = generate_reachable("hang-corners", 52, 0, true, ".");
  nlohmann::json j = r.scene;
  const Vec3 g = parse_scene(r.scene.dump(), r.name + ".json").cloth->gravity;
  j["cloth"]["gravity"] = {0.1 * g.x(), 0.1 * g.y(), 0.1 * g.z()};
  const Scene scene = parse_scene(j.dump(), r.name + "-light.json");
  std::vector<StrategyResult> runs;
  std::vector<std::vector<int>> budgets;
  for (const bool push : {false, true}) {
    Lines log;
    runs.push_back(run_half_window_plan(scene, 20, push, log));
    budgets.push_back(log.budgets);
  }
  ASSERT_TRUE(runs[1].uniform_push.has_value());
  const UniformPush& p = *runs[1].uniform_push;
  EXPECT_EQ(p.stop, FitStop::kBounded) << describe(p);
  EXPECT_GT(p.simulated, 1);
  EXPECT_EQ(budgets[1], budgets[0]);
  ASSERT_EQ(runs[1].stages.size(), runs[0].stages.size());
  for (size_t s = 0; s < runs[0].stages.size(); ++s) {
    EXPECT_EQ(runs[1].stages[s].evaluations, runs[0].stages[s].evaluations) << "stage " << s;
    EXPECT_EQ(runs[1].stages[s].objective_start, runs[0].stages[s].objective_start) << "stage " << s;
  }
  EXPECT_EQ(runs[1].evaluations, runs[0].evaluations);
}

// Not a check: the four gravity-tilt scenes the lattice stages stall on, along s·Δg and under the fit from no
// push. KEYFRAME_PUSH_SCENES="drop-collider-3 cape-wuson-0" picks the scenes (their files in the suite's
// scenes folder, Δg from the generator). Run with KEYFRAME_NO_FP_TRAPS=1: the generator's own flight of a cape
// on Testwuson.X divides by zero in the body query.
// Not a check: the strategy's fit on scene files (KEYFRAME_PUSH_SCENES, paths), the paying test off
// (KEYFRAME_PUSH_PAYING steps to turn it on), to read the cost after each step of the fits that paid and not.
TEST(UniformPush, DISABLED_TraceStrategyFits) {
  const char* env = std::getenv("KEYFRAME_PUSH_SCENES");
  const char* paying = std::getenv("KEYFRAME_PUSH_PAYING");
  std::istringstream list(env ? env : "");
  for (std::string path; list >> path;) {
    const Scene scene = load_scene(path);
    auto sys = make_system(scene);
    Problem problem(scene, scene.time, *sys);
    if (!problem.controls().forces()) continue;
    FewFitOptions o = uniform_push_options(scene, 100);
    o.paying_steps = paying ? std::atoi(paying) : 0;
    const double t0 = cpu_seconds();
    const UniformPush push = fit_uniform_push(problem, scene, o);
    std::cout << scene.name << ": " << describe(push) << "; " << cpu_seconds() - t0 << " CPU s" << std::endl;
  }
}

const std::filesystem::path kSuiteScenes = std::filesystem::path(KEYFRAME_SOURCE_DIR) / "tests/results/reachable/scenes";

// A suite scene by its name ("cape-wuson-0"): the generator's variant (Δg and the rest) and the scene file.
std::pair<ReachableScene, Scene> suite_scene(const std::string& name) {
  const size_t dash = name.rfind('-');
  return {generate_reachable(name.substr(0, dash), 52, std::stoi(name.substr(dash + 1)), false, kSuiteScenes),
          load_scene(kSuiteScenes / (name + ".json"))};
}

// Not a check: a global search over pushes before the fit. KEYFRAME_PUSH_SAMPLES (64) Halton points in the ball
// of half of gravity, flown forward; Levenberg–Marquardt (the strategy's options, paying test off) from the best
// three. Prints where the best samples and fits lie against the generator's Δg (KEYFRAME_PUSH_SCENES: names).
TEST(UniformPush, DISABLED_HaltonSearchBeforeTheFit) {
  const char* env = std::getenv("KEYFRAME_PUSH_SCENES");
  const char* samples_env = std::getenv("KEYFRAME_PUSH_SAMPLES");
  const int samples = samples_env ? std::atoi(samples_env) : 64;
  std::istringstream list(env ? env : "cape-wuson-0 cape-wuson-4 drop-collider-8");
  for (std::string name; list >> name;) {
    const auto [r, scene] = suite_scene(name);
    auto sys = make_system(scene);
    Problem problem(scene, scene.time, *sys);
    const std::vector<PlacedKeyframe> placed = placed_keyframes(problem, scene);
    VecX res(residual_count(placed));
    const FewFitOptions o0 = uniform_push_options(scene, 100);
    const double radius = o0.max_norm, t0 = cpu_seconds();
    std::vector<std::pair<double, Vec3>> flown;
    for (int k = 1; int(flown.size()) < samples; ++k) {
      const Vec3 a = radius * Vec3(2 * radical_inverse(k, 2) - 1, 2 * radical_inverse(k, 3) - 1, 2 * radical_inverse(k, 5) - 1);
      if (a.norm() > radius) continue;
      problem.evaluate(uniform_push_controls(problem, a), nullptr);
      const double worst = problem.last_diverged() ? INFINITY : keyframe_residuals(problem.rollout(), placed, true, res);
      flown.push_back({std::isfinite(worst) ? 0.5 * res.squaredNorm() : INFINITY, a});
    }
    std::sort(flown.begin(), flown.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    problem.evaluate(uniform_push_controls(problem, Vec3::Zero()), nullptr);
    keyframe_residuals(problem.rollout(), placed, true, res);
    const double none = 0.5 * res.squaredNorm();
    const Vec3 dg = r.variant.dg;
    std::cout << name << ": |dg| " << dg.norm() << ", " << samples << " samples in " << cpu_seconds() - t0
              << " CPU s; cost with none " << none << "\n";
    for (int b = 0; b < 3; ++b) {
      std::cout << "  sample " << b << ": cost " << flown[b].first / none << " of none's, |a-dg|/|dg| "
                << (flown[b].second - dg).norm() / dg.norm() << "\n";
      FewFitOptions o = o0;
      o.paying_steps = 0;
      FewVariableFit fitter(problem, scene, 3, [&problem](const VecX& y, VecX& z) {
        z = uniform_push_controls(problem, Vec3(y));
      }, o);
      VecX y = flown[b].second;
      double cost, worst, start;
      const double t1 = cpu_seconds();
      const FitStop stop = fitter.fit(y, cost, worst, start);
      std::cout << "    LM " << fit_stop_name(stop) << " after " << fitter.simulated() << " flights (" << cpu_seconds() - t1
                << " CPU s): cost " << cost / none << " of none's, worst keyframe " << worst / fitter.tolerance()
                << " tolerances, |a-dg|/|dg| " << (Vec3(y) - dg).norm() / dg.norm() << std::endl;
    }
  }
}

TEST(UniformPush, DISABLED_DiagnoseGeneratedTilts) {
  const char* env = std::getenv("KEYFRAME_PUSH_SCENES");
  std::istringstream list(env ? env : "drop-collider-3 drop-collider-8 cape-wuson-0 cape-wuson-4");
  for (std::string name; list >> name;) {
    const auto [r, scene] = suite_scene(name);
    auto sys = make_system(scene);
    Problem problem(scene, scene.time, *sys);
    const Vec3 dg = r.variant.dg;
    std::cout << name << ": p=" << sys->particles() << " steps=" << scene.time.steps() << " controls "
              << problem.controls().kind_name() << " from frame " << problem.controls().first_frame()
              << " dg=(" << dg.transpose() << ") |dg|=" << dg.norm() << "\n";
    const auto probe = [&](double s, const char* how) {
      const double t0 = cpu_seconds();
      const double phi = problem.evaluate(uniform_push_controls(problem, s * dg), nullptr);
      std::cout << "  s=" << s << how << ": phi " << phi << " keyframe terms " << keyframe_terms(problem) << " worst "
                << worst_miss(problem, scene) << " tol (" << cpu_seconds() - t0 << " CPU s a flight)\n";
    };
    const bool probes = !std::getenv("KEYFRAME_PUSH_H");
    for (double s : {0.0, 0.25, 0.5, 0.75, 0.9, 0.99, 0.999, 1.0, 1.001, 1.01, 1.1})
      if (probes) probe(s, "");
    // Under the step schedule of the exact push's flight (the last one, s = 1): is the jump a split step?
    probe(1.0, "");
    sys->hold_step_schedule(sys->step_schedule());
    for (double s : {0.9, 0.99, 0.999, 1.001, 1.01, 1.1})
      if (probes) probe(s, " (s = 1's schedule held)");
    sys->release_step_schedule();
    const char* steps = std::getenv("KEYFRAME_PUSH_H");  // the Jacobian's difference steps, m/s²
    std::istringstream hs(steps ? steps : "0.001");
    for (double h; hs >> h;)
    for (const double from : {0.0, 0.9}) {
      FewFitOptions o;
      o.max_simulations = 100;
      o.max_step = 5;
      o.difference_step = h;
      std::cout << "  difference step " << h << " m/s^2:";
      const double t0 = cpu_seconds();
      UniformPush push;
      if (from == 0) {
        push = fit_uniform_push(problem, scene, o);
      } else {  // the same fit from 0.9 Δg: how wide the exact push's basin is
        FewVariableFit fitter(problem, scene, 3, [&problem](const VecX& y, VecX& z) {
          z = uniform_push_controls(problem, Vec3(y));
        }, o);
        VecX y = from * dg;
        double cost, worst;
        push.stop = fitter.fit(y, cost, worst, push.start_cost);
        push.simulated = fitter.simulated();
        push.a = Vec3(y);
        push.z = uniform_push_controls(problem, push.a);
        push.cost = cost;
        push.worst_miss = worst / fitter.tolerance();
      }
      const double seconds = cpu_seconds() - t0;
      problem.evaluate(push.z, nullptr);
      std::cout << "  LM from " << from << " dg: " << describe(push) << "; " << seconds << " CPU s; keyframe terms "
                << keyframe_terms(problem) << " worst " << worst_miss(problem, scene) << " tol; |a-dg|/|dg| "
                << (push.a - dg).norm() / dg.norm() << std::endl;
    }
  }
}

}  // namespace
}  // namespace kf

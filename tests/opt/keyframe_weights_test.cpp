// Keyframes are met, effort is minimised (opt/keyframe_weights.h): on a toy chain whose scene weights let the
// effort trade a reachable keyframe away, the strategy raises that keyframe's weight until it is within its
// tolerance; optimizer.soft_keyframes keeps the trade-off; the result's problem is left at the scene's weights.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "opt/keyframe_weights.h"
#include "opt/strategy.h"
#include "scene/scene.h"
#include "toy_system.h"

namespace kf {
namespace {

// Per-frame forces on a 4-particle chain; the centre of mass at frame 20 is asked 0.9 m away, with α so large
// against the weight that the optimum of keyframe plus effort stops far short of it.
Scene traded_scene(bool soft) {
  return parse_scene(std::string(R"({"time": {"fps": 30, "substeps": 2, "frames": 24}, "cloth": {"nx": 2, "ny": 2},
    "objectives": [{"type": "center_of_mass", "frame": 20, "target": [2.0, 0.9, 0.2], "weight": 1},
                   {"type": "center_of_mass", "frame": 8, "target": [1.5, 0.35, -0.3], "weight": 1}],
    "controls": {"kind": "per_frame", "alpha": 3},
    "optimizer": {"split_schedule": "adaptive", "ftol_rel": 1e-10, "soft_keyframes": )") +
                         (soft ? "true" : "false") + "}}",
                     "keyframe_weights.json");
}

constexpr double kTolerance = 0.01;  // metres, the toy's judgement of a centre of mass

Vec3 com_at(const Problem& p, int frame) {
  const VecX& x = p.rollout().x[frame * p.time().substeps];
  Vec3 c = Vec3::Zero();
  for (int i = 0; i < x.size() / 3; ++i) c += x.segment<3>(3 * i);
  return c / double(x.size() / 3);
}

std::vector<double> misses(const Scene& scene, const Problem& p) {
  std::vector<double> out;
  for (const ObjectiveSpec& o : scene.objectives)
    out.push_back((com_at(p, o.frame) - std::get<CenterOfMassKeyframe>(o.kind).target).norm());
  return out;
}

struct Outcome {
  StrategyResult result;
  std::vector<std::string> lines;
  std::vector<double> final_misses;
};

Outcome run(const Scene& scene, int budget) {
  struct Log final : StrategyLog {
    std::vector<std::string>* lines;
    void say(const std::string& line) override { lines->push_back(line); }
    void evaluation(int, int, double, const EvaluationRecord&) override {}
  } log;
  Outcome out;
  log.lines = &out.lines;
  StrategyHooks hooks;
  hooks.make_system = [](double h) { return std::make_unique<test::ToySystem>(4, h); };
  hooks.keyframes_unmet = [&scene](Problem& p) {
    std::vector<bool> unmet;
    for (double m : misses(scene, p)) unmet.push_back(m > kTolerance);
    return unmet;
  };
  StagePlan plan;
  plan.stages = {{2, budget, std::nullopt}};
  StrategySetup setup{scene, plan};
  setup.system = hooks.make_system(scene.time.h());
  setup.start_time = scene.time;
  out.result = run_strategy(std::move(setup), hooks, log);
  out.result.problem->evaluate(out.result.z, nullptr);
  out.final_misses = misses(scene, *out.result.problem);
  return out;
}

TEST(KeyframeWeights, RaisedScalesMultiplyOnlyTheUnmetKeyframes) {
  const KeyframeWeightRule rule;
  EXPECT_EQ(raised_weight_scales({}, {true, false}, rule, 1), (std::vector<double>{10.0, 1.0}));
  EXPECT_EQ(raised_weight_scales({10.0, 1.0}, {true, true}, rule, 2), (std::vector<double>{1000.0, 100.0}));
  EXPECT_FALSE(any_unmet({false, false}));
  EXPECT_TRUE(any_unmet({false, true}));
}

TEST(KeyframeWeights, TheSceneWeightsTradeTheKeyframesAwayWhenSoft) {
  const Scene scene = traded_scene(/*soft=*/true);
  const Outcome r = run(scene, 300);
  EXPECT_EQ(r.result.weight_rounds, 0);
  EXPECT_TRUE(r.result.weight_scales.empty());
  ASSERT_TRUE(ended_early(r.result.reason)) << r.result.status;
  // The trade-off, not the budget, leaves both keyframes outside their tolerance (the later one far).
  EXPECT_GT(r.final_misses[0], 10 * kTolerance);
  EXPECT_GT(r.final_misses[1], kTolerance);
}

TEST(KeyframeWeights, AMissedKeyframesWeightIsRaisedUntilItIsMet) {
  const Outcome soft = run(traded_scene(true), 300);
  const Outcome hard = run(traded_scene(false), 300);
  const StrategyResult& r = hard.result;
  EXPECT_GE(r.weight_rounds, 1);
  ASSERT_EQ(r.weight_scales.size(), 2u);
  EXPECT_GE(r.weight_scales[0], 10.0);
  EXPECT_GE(r.weight_scales[1], 10.0);
  for (double m : hard.final_misses) EXPECT_LE(m, kTolerance);
  // Each round is its own stage from the best point, within the plan's evaluations.
  EXPECT_EQ(int(r.stages.size()), 1 + r.weight_rounds);
  EXPECT_LE(r.evaluations, 300);
  bool said = false;
  for (const auto& l : hard.lines) said |= l.rfind("keyframes outside their tolerance: weight of", 0) == 0;
  EXPECT_TRUE(said);
  // The result's problem is at the scene's weights: the effort it reports is the same term as the soft run's.
  EXPECT_TRUE(r.problem->weight_scales().empty());
  EXPECT_GT(r.problem->breakdown().back().second, soft.result.problem->breakdown().back().second);
}

TEST(KeyframeWeights, NoRoundWithoutEvaluationsLeft) {
  const Outcome r = run(traded_scene(false), 8);
  EXPECT_EQ(r.result.weight_rounds, 0);
  EXPECT_LE(r.result.evaluations, 8);
}

TEST(KeyframeWeights, ScaledTermsGiveAGradientThatMatchesCentralDifferences) {
  const Scene scene = traded_scene(false);
  test::ToySystem sys(4, scene.time.h());
  Problem p(scene, scene.time, sys);
  p.set_weight_scales({100.0, 3.0});
  VecX z = VecX::Zero(p.size());
  for (int i = 0; i < z.size(); ++i) z[i] = 0.05 * std::sin(1.3 * i);  // a perturbed point, not zero controls
  VecX g;
  p.evaluate(z, &g);
  for (int i : {0, 5, int(z.size()) / 2, int(z.size()) - 1}) {
    double fd[2];
    for (int s = 0; s < 2; ++s) {
      const double h = s ? 1e-4 : 1e-5;
      VecX a = z, b = z;
      a[i] += h;
      b[i] -= h;
      fd[s] = (p.evaluate(a, nullptr) - p.evaluate(b, nullptr)) / (2 * h);
    }
    EXPECT_NEAR(fd[0], fd[1], 1e-6 * (1 + std::abs(fd[0])));
    EXPECT_NEAR(g[i], fd[0], 1e-6 * (1 + std::abs(fd[0])));
  }
  // The scales multiply each keyframe term; the effort is the scene's.
  test::ToySystem sys1(4, scene.time.h());
  Problem unscaled(scene, scene.time, sys1);
  unscaled.evaluate(z, nullptr);
  p.evaluate(z, nullptr);
  EXPECT_NEAR(p.breakdown()[0].second, 100.0 * unscaled.breakdown()[0].second, 1e-12);
  EXPECT_NEAR(p.breakdown()[1].second, 3.0 * unscaled.breakdown()[1].second, 1e-12);
  EXPECT_DOUBLE_EQ(p.breakdown()[2].second, unscaled.breakdown()[2].second);
}

}  // namespace
}  // namespace kf

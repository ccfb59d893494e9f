// Judging keyframes against their tolerances, and the cause a failed optimisation is given: synthetic
// measures for the rules, small real scenes for the measurements behind the causes.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/trajectory.h"
#include "opt/diagnosis.h"
#include "opt/keyframes/keyframe_kind.h"
#include "scene/scene.h"

namespace kf {
namespace {

using nlohmann::json;

const char* kSheetOnSphere = R"({
  "time": {"fps": 30, "frames": 24},
  "cloth": {"nx": 12, "ny": 12, "width": 1.2, "height": 1.2, "mass": 0.4, "origin": [-0.6, 0.9, -0.6],
            "u_axis": [1, 0, 0], "v_axis": [0, 0, 1],
            "colliders": [{"type": "sphere", "center": [0, 0.5, 0], "radius": 0.3}, {"type": "ground"}]},
  "objectives": [{"type": "center_of_mass", "frame": 24, "target": [0.1, 0.5, 0]},
                 {"type": "position", "frame": 24, "particles": [0], "targets": [[-0.2, 0.2, -0.3]]}],
  "controls": {"kind": "per_frame"}})";

// A run standing still at state x for `frames` + 1 frames.
Trajectory standing(const VecX& x, int frames) {
  Trajectory t;
  t.particles = int(x.size() / 3);
  t.x.assign(size_t(frames) + 1, x);
  t.v.assign(size_t(frames) + 1, VecX::Zero(x.size()));
  return t;
}

// The sheet's 144 particles placed so that particle 0 is `pos_error` from its target (along x) and the
// centre of mass `com_error` from its own.
VecX sheet_state(double com_error, double pos_error) {
  const Vec3 q = Vec3(-0.2, 0.2, -0.3) + Vec3(pos_error, 0, 0);
  const Vec3 p = (144.0 * (Vec3(0.1, 0.5, 0) + Vec3(com_error, 0, 0)) - q) / 143.0;
  VecX x(3 * 144);
  for (int i = 0; i < 144; ++i) x.segment<3>(3 * i) = i == 0 ? q : p;
  return x;
}

TEST(Diagnosis, ClothKeyframesAreJudgedAgainstOneCentimetreOrOnePercentOfTheSheet) {
  const Scene scene = parse_scene(kSheetOnSphere, "sheet.json");
  const auto before = measure_keyframes(scene, standing(sheet_state(0.15, 0.30), 24));
  const auto after = measure_keyframes(scene, standing(sheet_state(0.011, 0.013), 24));
  EXPECT_NEAR(after[0].report.at("error").get<double>(), 0.011, 1e-12);
  EXPECT_NEAR(after[1].report.at("rms_error").get<double>(), 0.013, 1e-12);
  const auto k = judge_keyframes(scene, before, after);
  ASSERT_EQ(k.size(), 2u);
  EXPECT_EQ(k[0].name, "center_of_mass@24");
  EXPECT_TRUE(k[0].judged);
  EXPECT_NEAR(k[0].miss_before, 0.15 / 0.012, 1e-9);  // 1 % of 1.2 m beats 1 cm
  EXPECT_TRUE(k[0].met());
  EXPECT_FALSE(k[1].met());
  EXPECT_EQ(k[1].error_after, "1.30 cm");
  EXPECT_EQ(k[1].error_before, "30.00 cm");
  EXPECT_EQ(k[1].tolerance, "1.20 cm");
}

TEST(Diagnosis, FlockShapesNeedInsideAndCoverageOnlyWhereCoverageIsAsked) {
  const Scene scene = parse_scene(R"({"time": {"frames": 10}, "flock": {"agents": 10},
    "objectives": [{"type": "shape", "frame": 10, "polygon": [[0, 0], [5, 0], [5, 5]], "coverage": {"weight": 1}},
                   {"type": "shape", "frame": 10, "polygon": [[0, 0], [5, 0], [5, 5]]}]})",
                                  "flock.json");
  // Every agent inside, all in one corner: inside, but the region is not filled.
  VecX x(30);
  for (int i = 0; i < 10; ++i) x.segment<3>(3 * i) = Vec3(4.5 + 0.01 * i, 0, 0.2);
  const auto m = measure_keyframes(scene, standing(x, 10));
  const double coverage = m[0].report.at("coverage_fraction").get<double>();
  ASSERT_LT(coverage, 0.9);
  EXPECT_EQ(m[0].report.at("inside_fraction").get<double>(), 1.0);
  const auto k = judge_keyframes(scene, m, m);
  EXPECT_FALSE(k[0].met());
  EXPECT_NEAR(k[0].miss_after, (1 - coverage) / 0.1, 1e-12);
  EXPECT_TRUE(k[1].met());  // no coverage asked
  EXPECT_EQ(k[1].error_after, "inside 1.000");
  EXPECT_EQ(k[1].tolerance, "inside >= 0.95");
  // Three agents outside: 0.7 inside misses by (1 - 0.7) / (1 - 0.95) tolerances.
  for (int i = 0; i < 3; ++i) x.segment<3>(3 * i) = Vec3(-1, 0, 3);
  const auto out = judge_keyframes(scene, m, measure_keyframes(scene, standing(x, 10)));
  EXPECT_NEAR(out[1].miss_after, 0.3 / 0.05, 1e-9);
  EXPECT_EQ(out[1].error_after, "inside 0.700");
}

TEST(Diagnosis, SensitivityIsTheSameUnderTheRunsCheckpointingAndBudget) {
  const Scene scene = parse_scene(R"({"time": {"fps": 15, "substeps": 2, "frames": 12}, "flock": {"agents": 30},
    "objectives": [{"type": "shape", "frame": 12, "polygon": [[-2, 6], [2, 6], [2, 10], [-2, 10]],
                    "coverage": {"weight": 0.5}}]})",
                                  "flock.json");
  const Sensitivity all = measure_sensitivity(scene, scene.time);
  ASSERT_EQ(all.gradient_by_frame.size(), 12u);
  ASSERT_GT(all.gradient_by_frame.front(), 0.0);
  // Every 5th step kept, and a budget of 1 kB (far below keeping every step: the rollout checkpoints).
  for (const auto& [every, budget] : std::vector<std::pair<int, std::size_t>>{{5, 0}, {0, 1000}}) {
    const Sensitivity s = measure_sensitivity(scene, scene.time, every, budget);
    EXPECT_EQ(s.phi, all.phi);
    EXPECT_EQ(s.phi_noise, all.phi_noise);
    EXPECT_EQ(s.gradient_by_frame, all.gradient_by_frame) << "every " << every << ", budget " << budget;
    EXPECT_EQ(s.to_json().dump(), all.to_json().dump());
  }
}

std::vector<KeyframeJudgement> one_keyframe(double before, double after) {
  KeyframeJudgement k;
  k.name = "center_of_mass@24";
  k.judged = true;
  k.miss_before = before;
  k.miss_after = after;
  k.error_before = "15.00 cm";
  k.error_after = "5.00 cm";
  k.tolerance = "1.00 cm";
  return {k};
}

RunFacts facts(double start, double end, const std::string& status = "converged") {
  RunFacts f;
  f.status = status;
  f.budget = status.find("limit reached") != std::string::npos;
  f.keyframe_objective_start = start;
  f.keyframe_objective_end = end;
  f.objective_start = start;
  f.max_objective = start;
  return f;
}

// A start that is not noise (phi 15, round-off-level noise) whose gradient grows `growth` times.
Sensitivity quiet_start(double growth) {
  Sensitivity s;
  s.phi = 15;
  s.phi_noise = 1e-14;
  s.growth = s.growth_beyond_free = growth;
  return s;
}

TEST(Diagnosis, OutcomeFollowsProgressAndDistance) {
  const Sensitivity smooth;
  Diagnosis d = diagnose(one_keyframe(15, 0.5), smooth, facts(10, 0.01, "evaluation limit reached"));
  EXPECT_EQ(d.outcome, "reached");
  EXPECT_FALSE(d.failed());
  EXPECT_NE(d.line.find("budget"), std::string::npos) << d.line;
  d = diagnose(one_keyframe(15, 2), smooth, facts(10, 0.1));  // progress, within kFarMiss tolerances: still a miss
  EXPECT_EQ(d.outcome, "near");
  EXPECT_TRUE(d.failed());
  EXPECT_NE(d.line.find("not reached, but near"), std::string::npos) << d.line;
  d = diagnose(one_keyframe(15, 5), smooth, facts(10, 1));  // progress, but far
  EXPECT_EQ(d.outcome, "not_reached");
  EXPECT_TRUE(d.failed());
  d = diagnose(one_keyframe(15, 2), smooth, facts(10, 9));  // near, but no progress on the objective
  EXPECT_EQ(d.outcome, "no_progress");
  EXPECT_TRUE(d.failed());
  EXPECT_NE(d.line.find("no progress"), std::string::npos) << d.line;
}

TEST(Diagnosis, CauseNamesNoiseThenAmplificationThenBudgetThenReach) {
  Sensitivity s;
  s.phi = 15;
  s.phi_noise = 1.8;
  s.growth = s.growth_beyond_free = 1e12;
  s.grows_from_frame = 6;
  const auto k = one_keyframe(15, 14);
  EXPECT_NE(diagnose(k, s, facts(10, 9)).line.find("noise at the start"), std::string::npos);
  s.phi_noise = 1e-14;
  std::string line = diagnose(k, s, facts(10, 9)).line;
  EXPECT_NE(line.find("amplifies perturbations"), std::string::npos) << line;
  EXPECT_NE(line.find("frame 6"), std::string::npos) << line;
  s.growth = s.growth_beyond_free = 1.5;
  RunFacts f = facts(10, 9, "evaluation limit reached");
  f.evaluations = 300;
  f.recent_improvement = 0.5;
  line = diagnose(k, s, f).line;
  EXPECT_NE(line.find("budget ended it"), std::string::npos) << line;
  f.recent_improvement = 1;  // stalled at a large budget: no longer the budget's fault
  EXPECT_EQ(diagnose(k, s, f).line.find("budget ended it"), std::string::npos);
  line = diagnose(k, s, facts(10, 9)).line;
  EXPECT_NE(line.find("out of reach"), std::string::npos) << line;
  f = facts(10, 9);
  f.effort_end = 20;  // the effort outweighs what is left of the keyframes
  line = diagnose(k, s, f).line;
  EXPECT_NE(line.find("lower controls.alpha"), std::string::npos) << line;
  EXPECT_NE(line.find("effort is 69 %"), std::string::npos) << line;
  f = facts(10, 9);
  f.descent.linear_fraction = 1e-5;  // the slope holds over a sliver of the way: rough, not out of reach
  f.descent.phi = 2e-3;
  f.descent.grad_norm = 100;
  line = diagnose(k, s, f).line;
  EXPECT_NE(line.find("the objective is rough or stiff"), std::string::npos) << line;
  EXPECT_NE(line.find("a control change of 2e-10"), std::string::npos) << line;
  EXPECT_EQ(line.find("out of reach"), std::string::npos) << line;
  f.descent.linear_fraction = 0;  // not even the smallest step
  line = diagnose(k, s, f).line;
  EXPECT_NE(line.find("does not fall as the gradient predicts even over 1e-06"), std::string::npos) << line;
  f.descent.linear_fraction = 1e-2;
  EXPECT_NE(diagnose(k, s, f).line.find("out of reach"), std::string::npos);
}

// A crowd whose line search stalled among packed agents was told of sheets, colliders and friction.
TEST(Diagnosis, AFlocksCausesNameAgentsNotSheets) {
  Sensitivity s = quiet_start(1.5);
  const auto k = one_keyframe(15, 14);
  RunFacts f = facts(10, 9);
  f.flock = true;
  f.descent.linear_fraction = 1e-6;
  f.descent.phi = 2e-3;
  f.descent.grad_norm = 100;
  std::string line = diagnose(k, s, f).line;
  EXPECT_NE(line.find("the objective is rough or stiff"), std::string::npos) << line;
  EXPECT_NE(line.find("agents packed"), std::string::npos) << line;
  s.growth = s.growth_beyond_free = 1e12;
  s.grows_from_frame = 6;
  const std::string amplified = diagnose(k, s, f).line;
  EXPECT_NE(amplified.find("amplifies perturbations"), std::string::npos) << amplified;
  s.phi_noise = 1.8;
  const std::string noisy = diagnose(k, s, f).line;
  EXPECT_NE(noisy.find("agents spawned on top of each other"), std::string::npos) << noisy;
  for (const std::string& l : {line, amplified, noisy})
    for (const char* cloth_word : {"sheet", "collider", "cloth.", "friction"})
      EXPECT_EQ(l.find(cloth_word), std::string::npos) << cloth_word << " in: " << l;
}

// A 100,000-agent crowd's run: half its evaluations refused as unstable, the rest smooth; the budget ended
// it. The refusals are the cause named, not a collider or the effort; a few refusals are not.
TEST(Diagnosis, TrialsRefusedAsUnstableAreNamedWhenThereAreMany) {
  const Sensitivity s = quiet_start(90);
  const auto k = one_keyframe(15, 14);
  RunFacts f = facts(10, 9, "evaluation limit reached");
  f.flock = true;
  f.evaluations = 60;
  f.recent_improvement = 0.95;
  f.unstable_trials = 29;
  const std::string line = diagnose(k, s, f).line;
  EXPECT_NE(line.find("29 of its 60 evaluations"), std::string::npos) << line;
  EXPECT_NE(line.find("implicit_damping"), std::string::npos) << line;
  EXPECT_NE(line.find("time.substeps"), std::string::npos) << line;
  EXPECT_EQ(line.find("collider"), std::string::npos) << line;
  f.unstable_trials = 2;
  const std::string few = diagnose(k, s, f).line;
  EXPECT_EQ(few.find("refused as unstable"), std::string::npos) << few;
}

// A budget stop says how many more evaluations its own progress expects: the worst miss of 4 tolerances
// needs the keyframe terms 16x lower; falling 2x a tenth (30 evaluations) that is 4 tenths, 120 evaluations.
TEST(Diagnosis, ABudgetStopStatesTheEvaluationsItExpectsToNeed) {
  RunFacts f;
  f.evaluations = 300;
  f.recent_improvement = 0.5;
  EXPECT_EQ(expected_more_evaluations(f, 4.0), 120);
  EXPECT_EQ(expected_more_evaluations(f, 1.0), 0);  // nothing missed
  f.recent_improvement = 1.0;
  EXPECT_EQ(expected_more_evaluations(f, 4.0), 0);  // no longer falling: no estimate
  Sensitivity s;
  s.growth = s.growth_beyond_free = 1.5;
  RunFacts g = facts(10, 9, "evaluation limit reached");
  g.evaluations = 60;
  g.recent_improvement = 0.5;
  const std::string line = diagnose(one_keyframe(15, 4), s, g).line;
  EXPECT_NE(line.find("budget ended it after 60 evaluations"), std::string::npos) << line;
  EXPECT_NE(line.find("needs about 24 more"), std::string::npos) << line;
}

// A large flight's plan spends fewer evaluations than optimizer.max_evaluations: its stop says so, not "its budget".
TEST(Diagnosis, ALargeFlightsBudgetStopNamesThePlansShare) {
  Sensitivity s;
  s.growth = s.growth_beyond_free = 1.5;
  RunFacts f = facts(10, 9, "evaluation limit reached");
  f.evaluations = 69;
  f.recent_improvement = 0.5;
  f.max_evaluations = 300;
  const std::string plain = diagnose(one_keyframe(15, 4), s, f).line;
  EXPECT_NE(plain.find("(it stopped at its budget: evaluation limit reached)"), std::string::npos) << plain;
  f.scaled_budget = 69;
  const std::string line = diagnose(one_keyframe(15, 4), s, f).line;
  EXPECT_NE(line.find("(it stopped at the 69 of its 300 evaluations its plan gives a flight this large: evaluation "
                      "limit reached)"),
            std::string::npos)
      << line;
  EXPECT_EQ(line.find("its budget:"), std::string::npos) << line;
}

TEST(Diagnosis, ARunThatFellBackBelowItsResultSaysWhere) {
  Sensitivity s;
  s.growth = s.growth_beyond_free = 1.5;
  RunFacts f = facts(10, 4, "converged");
  const std::string plain = diagnose(one_keyframe(15, 4), s, f).line;
  f.fallback = "the result leaves center_of_mass@13 farther off than uncontrolled: the run ends at no control";
  const std::string line = diagnose(one_keyframe(15, 4), s, f).line;
  EXPECT_EQ(plain.find("farther off than uncontrolled"), std::string::npos) << plain;
  EXPECT_NE(line.find(f.fallback), std::string::npos) << line;
  EXPECT_EQ(line.find(plain), 0u) << line;  // the rest of the line is unchanged
  EXPECT_TRUE(diagnose(one_keyframe(15, 0.5), s, f).reached);  // a met keyframe stays met
}

}  // namespace
}  // namespace kf

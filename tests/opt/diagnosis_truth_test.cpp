// Diagnoses that say only what the run measured: a keyframe left at its uncontrolled error while another was
// met is named as such; noise at the start is blamed only when the run stayed near it (its keyframe terms fell
// less than tenfold); a run that
// stalled before its budget ended is not called out of reach. On a generated scene whose keyframes are
// reachable by construction (bench/bench_reachable.h), the failure names the keyframe left behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "app/optimize_job.h"
#include "bench/bench_reachable.h"
#include "opt/diagnosis.h"
#include "../sim/character_test_util.h"

namespace kf {
namespace {

KeyframeJudgement judged(const std::string& name, int frame, double before, double after, const std::string& eb,
                         const std::string& ea) {
  KeyframeJudgement k;
  k.name = name;
  k.frame = frame;
  k.judged = true;
  k.miss_before = before;
  k.miss_after = after;
  k.error_before = eb;
  k.error_after = ea;
  k.tolerance = "1.00 cm";
  return k;
}

RunFacts run(double start, double end, const std::string& status) {
  RunFacts f;
  f.status = status;
  f.budget = status.find("limit reached") != std::string::npos;
  f.keyframe_objective_start = f.objective_start = f.max_objective = start;
  f.keyframe_objective_end = end;
  f.evaluations = 300;
  return f;
}

Sensitivity noisy_start() {
  Sensitivity s;
  s.phi = 15;
  s.phi_noise = 1.8;  // relative noise 0.12
  return s;
}

TEST(DiagnosisTruth, AKeyframeLeftAtItsUncontrolledErrorWhileAnotherWasMetIsNamed) {
  const std::vector<KeyframeJudgement> k = {judged("center_of_mass@7", 7, 1.87, 1.86, "1.87 cm", "1.86 cm"),
                                            judged("position@15", 15, 9.0, 0.4, "9.00 cm", "0.40 cm")};
  for (const Sensitivity& s : {Sensitivity{}, noisy_start()}) {
    const std::string line = diagnose(k, s, run(10, 0.2, "converged")).line;
    EXPECT_NE(line.find("center_of_mass@7 was left at its uncontrolled error (1.86 cm, 1.87 cm uncontrolled) while "
                        "position@15 was met"),
              std::string::npos)
        << line;
    EXPECT_NE(line.find("an earlier keyframe"), std::string::npos) << line;
    EXPECT_EQ(line.find("noise at the start"), std::string::npos) << line;
    EXPECT_EQ(line.find("out of reach"), std::string::npos) << line;
  }
  // Both keyframes moved: not named so.
  const std::vector<KeyframeJudgement> moved = {judged("center_of_mass@7", 7, 9.0, 2.0, "9 cm", "2 cm"),
                                                judged("position@15", 15, 9.0, 0.4, "9 cm", "0.4 cm")};
  EXPECT_EQ(diagnose(moved, Sensitivity{}, run(10, 0.2, "converged")).line.find("uncontrolled error"),
            std::string::npos);
}

TEST(DiagnosisTruth, NoiseAtTheStartOnlyForARunThatNeverLeftIt) {
  const std::vector<KeyframeJudgement> k = {judged("position@15", 15, 9.0, 2.0, "9 cm", "2 cm")};
  EXPECT_NE(diagnose(k, noisy_start(), run(10, 9, "converged")).line.find("noise at the start"), std::string::npos);
  EXPECT_NE(diagnose(k, noisy_start(), run(10, 4, "converged")).line.find("noise at the start"), std::string::npos);
  const std::string line = diagnose(k, noisy_start(), run(10, 0.5, "converged")).line;  // fell 20x: left it
  EXPECT_EQ(line.find("noise at the start"), std::string::npos) << line;
}

TEST(DiagnosisTruth, AStallBeforeTheBudgetEndedIsNotCalledOutOfReach) {
  const std::vector<KeyframeJudgement> k = {judged("position@15", 15, 9.0, 2.0, "9 cm", "2 cm")};
  RunFacts f = run(10, 0.5, "evaluation limit reached");
  f.recent_improvement = 1;  // stalled: not the budget's fault
  const std::string line = diagnose(k, Sensitivity{}, f).line;
  EXPECT_EQ(line.find("out of reach"), std::string::npos) << line;
  EXPECT_NE(line.find("stopped falling"), std::string::npos) << line;
  EXPECT_NE(diagnose(k, Sensitivity{}, run(10, 0.5, "converged")).line.find("out of reach"), std::string::npos);
}

// A run whose effort is a negligible share of its objective is not told to reweigh it: a heavier keyframe or a
// lower alpha moves the same minimum. A rate that needs ten times the run's evaluations says so.
TEST(DiagnosisTruth, AStallWithNoEffortIsNotSentToTheWeights) {
  const std::vector<KeyframeJudgement> k = {judged("position@40", 40, 41.5, 19.6, "41.53 cm", "19.58 cm")};
  RunFacts f = run(5.5, 1.23, "evaluation limit reached");
  f.recent_improvement = 0.999;
  f.effort_end = 0;
  std::string line = diagnose(k, Sensitivity{}, f).line;
  EXPECT_EQ(line.find("raise the keyframe's weight"), std::string::npos) << line;
  EXPECT_NE(line.find("neither the keyframe's weight nor controls.alpha"), std::string::npos) << line;
  EXPECT_NE(line.find("more evaluations are not the remedy"), std::string::npos) << line;
  f.effort_end = 0.5;  // 29 % of the objective: the weights may decide it
  line = diagnose(k, Sensitivity{}, f).line;
  EXPECT_NE(line.find("raise the keyframe's weight"), std::string::npos) << line;
}

// The reduced generated drop onto a collider (two keyframes), cut to two evaluations a stage so that it fails
// (at its default budget it reaches): its diagnosis blames the budget and names no cause it did not measure.
// (Naming a keyframe left at its uncontrolled error is checked on judged keyframes above.)
TEST(DiagnosisTruth, GeneratedDropCutShortBlamesItsBudget) {
  test::TempDir dir;
  const ReachableScene r = generate_reachable("drop-collider", 52, 1, true, dir.path());
  std::ofstream(dir.path() / "scene.json") << r.scene.dump(1);
  OptimizeOptions opt;
  opt.quiet = true;
  opt.max_evaluations = 2;
  opt.out = (dir.path() / "run").string();
  const OptimizeOutcome outcome = optimize_job(dir.path() / "scene.json", opt);
  ASSERT_TRUE(outcome.failed) << "met its keyframes at two evaluations a stage: " << outcome.diagnosis;
  EXPECT_NE(outcome.diagnosis.find("its budget ended it"), std::string::npos) << outcome.diagnosis;
  EXPECT_EQ(outcome.diagnosis.find("out of reach"), std::string::npos) << outcome.diagnosis;
  EXPECT_EQ(outcome.diagnosis.find("noise at the start"), std::string::npos) << outcome.diagnosis;
  std::ifstream in(dir.path() / "run" / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_TRUE(report.at("diagnosis").at("failed").get<bool>());
}

// The generated suite's committed reports (tests/results/reachable/*/reports): a failure's diagnosis says
// "noise at the start" only where the run measured a noisy start and its keyframe terms stayed above a tenth
// of where they began, and "out of reach" only for a run that stopped on its own (not at a budget or a cut),
// with smooth dynamics, at keyframe terms its raised weights (if any) did not bring down further.
TEST(DiagnosisTruth, CommittedGeneratedFailuresNameOnlyWhatTheyMeasured) {
  namespace fs = std::filesystem;
  const fs::path root = fs::path(KEYFRAME_SOURCE_DIR) / "tests/results/reachable";
  int reports = 0;
  for (const auto& dir : fs::directory_iterator(root)) {
    if (!fs::is_directory(dir.path() / "reports")) continue;
    for (const auto& file : fs::directory_iterator(dir.path() / "reports")) {
      std::ifstream in(file.path());
      const nlohmann::json r = nlohmann::json::parse(in);
      ++reports;
      const nlohmann::json& d = r.at("diagnosis");
      if (!d.at("failed").get<bool>()) continue;
      const std::string line = d.at("diagnosis").get<std::string>();
      const std::string where = file.path().string() + ": " + line;
      if (line.find("noise at the start") != std::string::npos) {
        EXPECT_GT(r.at("sensitivity").at("objective_relative_noise_start").get<double>(), 1e-6) << where;
        EXPECT_GT(d.at("keyframe_objective_end").get<double>(), 0.1 * d.at("keyframe_objective_start").get<double>())
            << where;
      }
      if (line.find("out of reach") != std::string::npos) {
        EXPECT_FALSE(d.at("budget_reached").get<bool>()) << where;
        EXPECT_EQ(line.find("diverged"), std::string::npos) << where;
      }
    }
  }
  EXPECT_GE(reports, 12);
}

}  // namespace
}  // namespace kf

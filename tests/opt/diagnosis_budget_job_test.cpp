// Through the real binary: a generated scene (reduced, bench/bench_reachable.h) cut to a small budget stops at
// it, and its diagnosis says what more evaluations are expected to bring (or that so few cannot tell), whichever
// cause it names. Dropped sheets on colliders are the class whose near misses stop at their budget in motion
// that amplifies perturbations (tests/results/reachable/README.md, "Near misses and the budget").
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "bench/bench_reachable.h"
#include "core/error.h"
#include "../support/cli_test.h"

namespace kf {
namespace {
using namespace cli_test;

class DiagnosisBudgetJob : public TempDirTest {};

TEST_F(DiagnosisBudgetJob, ADroppedSheetCutToItsBudgetSaysWhatMoreEvaluationsWouldBring) {
  int budget_stops = 0;
  for (int index = 0; index < 3; ++index) {
    ReachableScene r = generate_reachable("drop-collider", 52, index, true, dir_);
    r.scene["optimizer"]["max_evaluations"] = 15;
    write(r.name + ".json", r.scene.dump(1));
    const reliability::CliResult run = run_keyframe("optimize " + r.name + ".json --out " + r.name + " --quiet", dir_);
    ASSERT_TRUE(run.code == 0 || run.code == kExitNotReached) << run.output;
    const Json report = Json::parse(read_text(dir_ / r.name / "report.json"));
    const std::string line = report.at("diagnosis").at("diagnosis").get<std::string>();
    if (report.at("diagnosis").at("reached").get<bool>() || line.find("it stopped at its budget") == std::string::npos)
      continue;
    ++budget_stops;
    const bool expects = line.find("more to come within its tolerance") != std::string::npos ||
                         line.find("more evaluations to come within its tolerance") != std::string::npos ||
                         line.find("too few evaluations to tell how many more it needs") != std::string::npos;
    EXPECT_TRUE(expects) << r.name << ": " << line;
  }
  EXPECT_GT(budget_stops, 0) << "no scene stopped at its budget unmet: the test checks nothing";
}

}  // namespace
}  // namespace kf

// Interrupting an optimisation with SIGINT saves the best controls; --resume finishes the job.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "app/optimize_job.h"
#include "core/error.h"
#include "../support/interrupted_run.h"
#include "../reliability/cli_harness.h"

namespace kf {
namespace {
namespace fs = std::filesystem;
using test::run_keyframe_interrupted;

const char* kScene = R"({
  "seed": 3,
  "time": {"fps": 30, "frames": 60},
  "flock": {"agents": 100, "spawn": {"radius": 7, "velocity": [0, 0, 1]}},
  "objectives": [
    {"type": "center_of_mass", "frame": 30, "target": [2, 0, 2]},
    {"type": "center_of_mass", "frame": 60, "target": [0, 0, 5]}
  ],
  "controls": {"kind": "per_step", "alpha": 0.001},
  "optimizer": {"max_evaluations": 400, "ftol_rel": 1e-12}
})";

double final_objective(const fs::path& run) {
  std::ifstream in(run / "report.json");
  return nlohmann::json::parse(in).at("final_objective").get<double>();
}

TEST(Resume, InterruptedThenResumedRunMatchesAnUninterruptedOne) {
  const fs::path dir = fs::temp_directory_path() / ("keyframe_resume_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "small.json") << kScene;

  // At default settings the flock first converges short of its keyframes, then reaches them in stages with
  // their weights raised (opt/keyframe_weights.h); interrupts in those stages are covered below.
  const int whole_code = run_keyframe_interrupted(dir, {"optimize", "small.json", "--out", "whole"});
  ASSERT_TRUE(whole_code == 0 || whole_code == kExitNotReached) << whole_code;
  const double whole = final_objective(dir / "whole");
  const int whole_evaluations = nlohmann::json::parse(std::ifstream(dir / "whole" / "report.json")).at("evaluations");

  // Cut in the first stage (3 evaluations) and in a stage with raised keyframe weights (40).
  for (const int cut_after : {3, 40}) {
    SCOPED_TRACE("interrupted after " + std::to_string(cut_after) + " evaluations");
    const std::string cut = "cut" + std::to_string(cut_after);
    EXPECT_EQ(run_keyframe_interrupted(dir, {"optimize", "small.json", "--out", cut}, cut_after), kExitInterrupted);
    std::ifstream report(dir / cut / "report.json");
    const auto j = nlohmann::json::parse(report);
    EXPECT_TRUE(j.at("interrupted").get<bool>());
    EXPECT_LT(j.at("evaluations").get<int>(), whole_evaluations) << "the interrupted run had already finished";
    if (cut_after == 3) {
      EXPECT_EQ(j.at("stage_results").size(), 1u) << "cut after the first stage";
    } else {
      EXPECT_GT(j.at("keyframe_weight_scales").at(0).get<double>(), 1.0) << "cut before the weights were raised";
    }

    EXPECT_EQ(run_keyframe_interrupted(dir, {"optimize", "--resume", cut}), whole_code);
    const double resumed = final_objective(dir / cut);
    EXPECT_NEAR(resumed, whole, 1e-3 * whole + 1e-9) << "uninterrupted " << whole << ", resumed " << resumed;
    EXPECT_EQ(reliability::read_text(dir / cut / "controls.bin"), reliability::read_text(dir / "whole" / "controls.bin"));
  }
  if (!HasFailure()) fs::remove_all(dir);
}

}  // namespace
}  // namespace kf

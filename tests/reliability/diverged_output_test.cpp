// Runs whose simulation diverges, through the real `keyframe` binary: a flock trial that blows up counts as
// diverged (a large finite objective, exit 7 with the reason) and leaves no non-finite value in
// trajectory.bin, controls.bin, report.json or iterations.csv; `gradcheck` at diverging controls says so instead of
// reporting an error of 0; and `gradcheck --at` refuses a controls.bin that is not a regular file.
#include <sys/stat.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "core/trajectory.h"
#include "opt/controls_file.h"

namespace kf::reliability {
namespace {

// A 10-agent flock that the explicit step cannot hold: nearly massless agents pushed apart hard, or a drag
// far beyond what a step of one second can integrate.
std::string blowing_up_flock(const std::string& fps, const std::string& flock) {
  return R"({"seed": 3, "time": {"fps": )" + fps + R"(, "frames": 20},
  "flock": {"agents": 10, )" + flock + R"(, "spawn": {"radius": 3, "velocity": [0, 0, 1]}},
  "objectives": [{"type": "center_of_mass", "frame": 20, "target": [1, 0, 2]}],
  "controls": {"kind": "per_frame", "alpha": 0.01},
  "optimizer": {"max_evaluations": 8}})";
}

bool json_all_finite(const nlohmann::json& j) {
  if (j.is_number_float()) return std::isfinite(j.get<double>());
  if (j.is_structured())
    for (const auto& v : j)
      if (!json_all_finite(v)) return false;
  return true;
}

class DivergedOutput : public TempDirTest {
 protected:
  void expect_finite_outputs(const std::string& scene) {
    write("s.json", scene);
    const CliResult r = run_keyframe("optimize s.json --quiet --out run", dir_);
    ASSERT_EQ(r.code, 7) << r.output;
    EXPECT_NE(r.output.find("keyframe: no progress"), std::string::npos) << r.output;
    const Trajectory t = load_trajectory(dir_ / "run/trajectory.bin");
    ASSERT_EQ(t.frames(), 21);
    for (int f = 0; f < t.frames(); ++f) {
      EXPECT_TRUE(t.x[size_t(f)].allFinite()) << "frame " << f;
      EXPECT_TRUE(t.v[size_t(f)].allFinite()) << "frame " << f;
    }
    int substeps = 0;
    EXPECT_TRUE(load_controls(dir_ / "run/controls.bin", &substeps).allFinite());
    const std::string report = read_text(dir_ / "run/report.json");
    EXPECT_TRUE(json_all_finite(nlohmann::json::parse(report)));
    EXPECT_EQ(report.find("NaN"), std::string::npos);
    // A diverged evaluation has no terms: its cells are empty, never nan or inf.
    const std::string history = read_text(dir_ / "run/iterations.csv");
    for (const char* bad : {"nan", "inf", "NaN", "Inf"}) EXPECT_EQ(history.find(bad), std::string::npos) << history;
  }
};

TEST_F(DivergedOutput, LightAgentsPushedHardLeaveOnlyFiniteValues) {
  expect_finite_outputs(blowing_up_flock("30", R"("mass": 1e-3, "avoidance": {"strength": 1e4})"));
}

TEST_F(DivergedOutput, StrongDragAtOneFrameASecondLeavesOnlyFiniteValues) {
  expect_finite_outputs(blowing_up_flock("1", R"("drag": {"strength": 100})"));
}

TEST_F(DivergedOutput, GradcheckAtDivergingControlsWarnsAndComparesNothing) {
  write("s.json", blowing_up_flock("30", R"("mass": 1e-3, "avoidance": {"strength": 1e4})"));
  const CliResult r = run_keyframe("gradcheck s.json --perturb 0 --samples 4", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("keyframe: warning: s.json: the simulation diverges at these controls (step "),
            std::string::npos)
      << r.output;
  const std::string json_line = r.output.substr(r.output.find('{'));
  const nlohmann::json j = nlohmann::json::parse(json_line);
  EXPECT_EQ(j["diverged"], true);
  EXPECT_TRUE(j["max_rel_error"].is_null());
  EXPECT_TRUE(j["cosine"].is_null());
  EXPECT_EQ(j["checked"], 0);
}

TEST_F(DivergedOutput, GradcheckAtAFifoControlsFileIsRefusedWithoutWaiting) {
  write("s.json", small_flock_scene());
  fs::create_directories(dir_ / "run");
  ASSERT_EQ(::mkfifo((dir_ / "run/controls.bin").c_str(), 0600), 0);
  const std::vector<std::string> before = list_tree(dir_);
  const CliResult r = run_keyframe("gradcheck s.json --at run", dir_);
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_EQ(r.output, "keyframe: error: run/controls.bin: not a regular file\n");
  EXPECT_EQ(list_tree(dir_), before);
}

TEST_F(DivergedOutput, InspectErrorNamingAFileWithANewlineIsOneLine) {
  for (const char* name : {"a\nb.obj", "a\nb.json"}) {
    const std::string shown = std::string(name).replace(1, 1, "\\n");
    if (std::string(name).ends_with(".json")) write(name, "{\"flock\": {\"agents\": 0}}");
    const CliResult r = run_keyframe("inspect \"$(printf '" + shown + "')\"", dir_);
    EXPECT_EQ(r.code, 3) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_EQ(r.output.rfind("keyframe: error: " + shown + ": ", 0), 0u) << r.output;
  }
}

}  // namespace
}  // namespace kf::reliability

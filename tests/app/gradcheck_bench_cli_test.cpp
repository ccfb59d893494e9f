// keyframe gradcheck and keyframe bench from the command line: the JSON and CSV a user reads.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <sstream>

#include "../reliability/cli_harness.h"
#include "core/error.h"

namespace kf {
namespace {

namespace fs = std::filesystem;
using reliability::run_keyframe;

class GradcheckBenchCli : public reliability::TempDirTest {};

// stdout alone (progress goes to stderr), so it must parse as one JSON object.
nlohmann::json stdout_json(const std::string& args, const fs::path& cwd) {
  const std::string cmd = "cd '" + cwd.string() + "' && '" KEYFRAME_BINARY "' " + args + " 2>/dev/null";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  EXPECT_EQ(pclose(p), 0) << args;
  return nlohmann::json::parse(out);
}

TEST_F(GradcheckBenchCli, GradcheckPrintsOneJsonObjectWithTheChecksNumbers) {
  const std::string scenes = KEYFRAME_SOURCE_DIR "/scenes/";
  const auto cloth =
      stdout_json("gradcheck " + scenes + "cloth-gradcheck.json --frames 3 --samples 6 --perturb 0.01", dir_);
  SCOPED_TRACE(cloth.dump());
  for (const char* key : {"scene", "adjoint", "solver", "checked", "kinks", "max_rel_error", "cosine",
                          "rel_error_norm", "fd_spread", "phi_noise", "grad_norm", "steps", "control_variables"})
    EXPECT_TRUE(cloth.contains(key)) << key;
  EXPECT_EQ(cloth["scene"], "cloth-gradcheck");
  EXPECT_EQ(cloth["adjoint"], "exact");
  EXPECT_EQ(cloth["solver"], "direct");
  EXPECT_EQ(cloth["checked"], 6);
  EXPECT_EQ(cloth["kinks"], 0);
  EXPECT_EQ(cloth["steps"], 6);  // 3 frames of the scene's 2 steps each
  EXPECT_GT(cloth["grad_norm"].get<double>(), 0);
  EXPECT_LE(cloth["max_rel_error"].get<double>(), 1e-6);
  EXPECT_GT(cloth["cosine"].get<double>(), 1 - 1e-9);

  // The swap adjoint is the paper's approximation: at perturbed controls it reads visibly worse.
  const auto swap = stdout_json(
      "gradcheck " + scenes + "cloth-gradcheck.json --frames 3 --samples 6 --perturb 0.1 --adjoint swap", dir_);
  EXPECT_EQ(swap["adjoint"], "swap");
  EXPECT_GT(swap["max_rel_error"].get<double>(), 1e-4) << swap.dump();

  const auto flock = stdout_json("gradcheck " + scenes + "square.json --frames 4 --samples 6 --perturb 0.01", dir_);
  EXPECT_EQ(flock["checked"], 6) << flock.dump();
  EXPECT_LE(flock["max_rel_error"].get<double>(), 1e-5) << flock.dump();

  const auto bad = run_keyframe("gradcheck " + scenes + "square.json --dt 0.03", dir_);
  EXPECT_NE(bad.code, kExitOk);
  EXPECT_NE(bad.output.find("--dt"), std::string::npos) << bad.output;
}

// Where an optimisation stopped: the check at a run's own controls, and φ along the negative gradient there,
// which at the smallest step falls as the gradient predicts (the probe that tells a kink from a bad gradient).
TEST_F(GradcheckBenchCli, GradcheckAtARunsControlsProbesTheDescentLine) {
  const std::string scene = KEYFRAME_SOURCE_DIR "/scenes/square.json";
  ASSERT_EQ(run_keyframe("optimize " + scene + " --max-evaluations 3 --quiet --out run", dir_).code, 7);  // not reached in 3
  const auto at = stdout_json("gradcheck " + scene + " --at run --samples 4 --line 8", dir_);
  SCOPED_TRACE(at.dump());
  EXPECT_LE(at["max_rel_error"].get<double>(), 1e-5);
  ASSERT_EQ(at["line"].size(), 8u);
  const double phi = at["phi"].get<double>(), g = at["grad_norm"].get<double>();
  const auto& first = at["line"][0];
  EXPECT_LT(first["phi"].get<double>(), phi);
  EXPECT_NEAR(first["phi"].get<double>(), first["predicted"].get<double>(), 1e-3 * first["step"].get<double>() * g);
  double previous = 0;
  for (const auto& p : at["line"]) {  // steps grow
    EXPECT_GT(p["step"].get<double>(), previous);
    previous = p["step"].get<double>();
  }

  // Controls of another length (the scene shortened) are refused with what was found and expected.
  const auto bad = run_keyframe("gradcheck " + scene + " --at run --frames 4", dir_);
  EXPECT_EQ(bad.code, kExitInput) << bad.output;
  EXPECT_NE(bad.output.find("run/controls.bin: holds"), std::string::npos) << bad.output;
}

TEST_F(GradcheckBenchCli, TinyFlockBenchWritesItsCsvPlotAndSummary) {
  const std::string crowd = " --crowd-scene " KEYFRAME_SOURCE_DIR "/scenes/square.json --crowd-agents 40 "
                            "--crowd-evaluations 2 --crowd-budget-agents 40 --crowd-budget 0.0001";
  const auto r = run_keyframe(
      "bench --only flock --agents 20,40 --flock-frames 5 --flock-evaluations 3 --out b" + crowd, dir_);
  ASSERT_EQ(r.code, kExitOk) << r.output;
  std::ifstream csv(dir_ / "b/flock_agents.csv");
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("agents,steps,control_variables,forward_s,gradient_s,grad_cosine,grad_rel_error,", 0), 0u)
      << header;
  std::vector<std::vector<std::string>> rows;
  while (std::getline(csv, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    rows.push_back(cells);
  }
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0][0], "20");
  EXPECT_EQ(rows[1][0], "40");
  EXPECT_EQ(std::stoi(rows[1][2]), 2 * std::stoi(rows[0][2]));  // controls grow with the agents
  for (const auto& row : rows) {
    EXPECT_GT(std::stod(row[3]), 0);  // forward seconds
    EXPECT_GT(std::stod(row[4]), 0);  // gradient seconds
    EXPECT_EQ(row[5], "");            // no finite-difference check asked for: left empty, not 0
    EXPECT_EQ(row[6], "");
    EXPECT_LT(std::stod(row[8]), std::stod(row[7]));  // the short optimisation lowered the keyframe error
  }
  std::ifstream png(dir_ / "b/flock_agents.png", std::ios::binary);
  char magic[8] = {};
  png.read(magic, 8);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
  std::ifstream summary_file(dir_ / "b/summary.json");
  const auto summary = nlohmann::json::parse(summary_file);
  EXPECT_TRUE(std::isfinite(summary["flock"]["gradient_exponent"].get<double>())) << summary.dump();

  // The crowd sweep: the square figure scaled to 40 agents, once as it is and once under a budget far
  // below what keeping every step needs, which checkpoints.
  std::ifstream crowd_csv(dir_ / "b/flock_crowd.csv");
  std::getline(crowd_csv, header);
  EXPECT_EQ(header.rfind("agents,control_variables,steps,max_memory_gb,checkpoint_every,evaluations,optimize_s,"
                         "s_per_evaluation,peak_mb,",
                         0),
            0u)
      << header;
  std::vector<std::vector<std::string>> crowd_rows;
  while (std::getline(crowd_csv, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    crowd_rows.push_back(cells);
  }
  ASSERT_EQ(crowd_rows.size(), 2u);
  for (const auto& row : crowd_rows) {
    EXPECT_EQ(row[0], "40");
    EXPECT_EQ(row[5], "2");           // evaluations
    EXPECT_GT(std::stod(row[8]), 1);  // peak MB of the child process
    ASSERT_EQ(row.size(), 20u);
    EXPECT_GT(std::stod(row[13]), 0);  // CPU seconds of the child process
    for (int c : {14, 15}) {           // coverage fractions of the square and the cross
      EXPECT_GE(std::stod(row[c]), 0);
      EXPECT_LE(std::stod(row[c]), 1);
    }
    EXPECT_GT(std::stod(row[16]), 0);  // the first evaluation's seconds
    EXPECT_GT(std::stod(row[17]), 0);  // the last one's
    EXPECT_GT(std::stod(row[18]), 0);  // neighbours per agent, uncontrolled
    EXPECT_GT(std::stod(row[19]), 0);  // and optimised
  }
  EXPECT_EQ(crowd_rows[0][4], "0");
  EXPECT_GT(std::stoi(crowd_rows[1][4]), 1) << "the budget must switch checkpointing on";
  EXPECT_TRUE(summary["crowd"]["evaluation_exponent"].is_null()) << "one size has no slope";
  std::ifstream dropped(dir_ / "b/crowd/square-40.json");
  EXPECT_EQ(nlohmann::json::parse(dropped)["objectives"][0].count("coverage"), 0u);

  EXPECT_EQ(nlohmann::json::parse(std::ifstream(dir_ / "b/crowd/square-40.json"))["objectives"][0]["weight"], 1);

  // With coverage kept and the weights scaled: its own table, the scaled scenes keep the terms, and every
  // keyframe weight (coverage too) is the figure's times sqrt(40 / 200).
  const auto c = run_keyframe("bench --only flock --agents 20 --flock-frames 5 --flock-evaluations 1 --out c "
                              "--crowd-scene " KEYFRAME_SOURCE_DIR "/scenes/square.json --crowd-agents 40 "
                              "--crowd-evaluations 2 --crowd-coverage --crowd-scale-weights",
                              dir_);
  ASSERT_EQ(c.code, kExitOk) << c.output;
  EXPECT_TRUE(std::filesystem::exists(dir_ / "c/flock_crowd_coverage_weighted.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir_ / "c/flock_crowd_coverage_weighted_time.png"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "c/flock_crowd.csv"));
  const auto kept = nlohmann::json::parse(std::ifstream(dir_ / "c/crowd/square-40-coverage-weighted.json"));
  for (const auto& objective : kept["objectives"]) {
    EXPECT_DOUBLE_EQ(objective["weight"].get<double>(), std::sqrt(0.2));
    EXPECT_DOUBLE_EQ(objective["coverage"]["weight"].get<double>(), 0.3 * std::sqrt(0.2));
  }
}

// The solver sweep on two tiny sheets: one column triple per solver and thread count, every cell measured
// (the sheets are small enough for the direct solve), and names outside the list refused.
TEST_F(GradcheckBenchCli, TinySolverBenchHasAColumnPerSolverAndRefusesUnknownNames) {
  const auto r = run_keyframe(
      "bench --only solver --solver-resolutions 6,8 --solvers pcg,mg-1e-6,auto,direct --threads 1 --solver-frames 1 "
      "--blender-n 0 --no-motion-table --out s",
      dir_);
  ASSERT_EQ(r.code, kExitOk) << r.output;
  std::ifstream csv(dir_ / "s/solver.csv");
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header,
            "n,particles,pcg_t1_forward_ms,pcg_t1_gradient_ms,pcg_t1_gradient_over_forward,mg-1e-6_t1_forward_ms,"
            "mg-1e-6_t1_gradient_ms,mg-1e-6_t1_gradient_over_forward,auto_t1_forward_ms,auto_t1_gradient_ms,"
            "auto_t1_gradient_over_forward,direct_t1_forward_ms,direct_t1_gradient_ms,direct_t1_gradient_over_forward");
  int rows = 0;
  while (std::getline(csv, line)) {
    ++rows;
    std::stringstream ss(line);
    std::string cell;
    for (int c = 0; std::getline(ss, cell, ','); ++c) {
      if (c >= 2) {
        EXPECT_GT(std::stod(cell), 0) << line;
      }
    }
  }
  EXPECT_EQ(rows, 2);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "s/solver_motion.csv"));
  for (const char* bad : {"mg-2", "ilu", "pcg-x"}) {
    const auto b = run_keyframe(std::string("bench --only solver --solvers ") + bad + " --out t", dir_);
    EXPECT_NE(b.code, kExitOk) << bad;
    EXPECT_NE(b.output.find("expected pcg, mg, auto"), std::string::npos) << b.output;
  }
}

}  // namespace
}  // namespace kf

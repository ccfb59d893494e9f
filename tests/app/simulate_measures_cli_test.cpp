// keyframe simulate as a dry run: each keyframe judged on the uncontrolled motion, printed one a line and
// written to report.json as optimize writes it; and the trajectory it saves read back as a CSV table.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/optimize_job.h"
#include "core/error.h"
#include "../support/cli_test.h"

namespace kf {
namespace {
using namespace cli_test;

class SimulateMeasures : public TempDirTest {};

// The rows of a CSV file, each split at commas.
std::vector<std::vector<std::string>> csv_rows(const fs::path& file) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(read_text(file));
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> row;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(cell);
    rows.push_back(row);
  }
  return rows;
}

// 5 x 5 cloth pinned at its top corners, 10 frames, one centre-of-mass keyframe far from where it hangs
// and one position keyframe on particle 0 near where it starts.
const char* kCloth = R"({"seed": 3, "time": {"fps": 30, "frames": 10},
  "cloth": {"nx": 5, "ny": 5, "width": 1, "height": 1, "pins": "top_corners"},
  "objectives": [{"type": "center_of_mass", "frame": 10, "target": [0.5, 0, 0.3]},
                 {"type": "position", "frame": 4, "particles": [0], "targets": [[0, 0, 0]]}],
  "controls": {"kind": "per_frame", "alpha": 0.01},
  "optimizer": {"max_evaluations": 6},
  "render": {"width": 64, "height": 48}})";

TEST_F(SimulateMeasures, PrintsAndReportsEachKeyframesMissAndTheCsvAgrees) {
  write("cloth.json", kCloth);
  const auto r = run_keyframe("simulate cloth.json --out run", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  const Json report = Json::parse(read_text(dir_ / "run/report.json"));
  ASSERT_EQ(report["measures"].size(), 2u) << report.dump();
  ASSERT_EQ(report["keyframe_errors"].size(), 2u) << report.dump();
  const Json& com = report["keyframe_errors"][0];
  EXPECT_EQ(com["name"], "center_of_mass@10");
  EXPECT_TRUE(com["judged"].get<bool>());
  EXPECT_FALSE(com["met"].get<bool>());
  EXPECT_EQ(com["tolerance"], "1.00 cm");
  const double error = report["measures"][0]["error"].get<double>();
  EXPECT_GT(error, 0.05);  // it hangs well away from the target
  EXPECT_NEAR(com["miss_after"].get<double>(), error / 0.01, 1e-9);
  // The printed line, after the line that says what was simulated.
  char line[128];
  std::snprintf(line, sizeof line, "\ncenter_of_mass@10: %.2f cm from its target (tolerance 1.00 cm, not met)\n",
                100 * error);
  EXPECT_NE(r.output.find(line), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("\nposition@4: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" from its targets (RMS) (tolerance 1.00 cm, "), std::string::npos) << r.output;

  // The same miss recomputed from the exported table: the mean position at frame 10 against the target.
  const auto e = run_keyframe("export run --format csv", dir_);
  ASSERT_EQ(e.code, 0) << e.output;
  const auto rows = csv_rows(dir_ / "run/export/trajectory.csv");
  ASSERT_EQ(rows.size(), 1u + 11u * 25u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"frame", "seconds", "particle", "x", "y", "z", "vx", "vy", "vz"}));
  double mean[3] = {0, 0, 0};
  int counted = 0;
  for (size_t k = 1; k < rows.size(); ++k) {
    ASSERT_EQ(rows[k].size(), 9u);
    if (std::stoi(rows[k][0]) != 10) continue;
    EXPECT_NEAR(std::stod(rows[k][1]), 10.0 / 30.0, 1e-15);
    for (int c = 0; c < 3; ++c) mean[c] += std::stod(rows[k][3 + c]) / 25;
    ++counted;
  }
  EXPECT_EQ(counted, 25);
  const double target[3] = {0.5, 0, 0.3};
  const double miss = std::hypot(mean[0] - target[0], mean[1] - target[1], mean[2] - target[2]);
  EXPECT_NEAR(miss, error, 1e-12);
}

// What simulate reports is what optimize reports for its uncontrolled start.
TEST_F(SimulateMeasures, AgreesWithOptimizesUncontrolledStart) {
  write("cloth.json", kCloth);
  ASSERT_EQ(run_keyframe("simulate cloth.json --out sim", dir_).code, 0);
  const auto o = run_keyframe("optimize cloth.json --out opt", dir_);
  ASSERT_TRUE(o.code == 0 || o.code == kExitNotReached) << o.output;
  const Json sim = Json::parse(read_text(dir_ / "sim/report.json"));
  const Json opt = Json::parse(read_text(dir_ / "opt/report.json"));
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(sim["keyframe_errors"][k]["name"], opt["keyframe_errors"][k]["name"]);
    // simulate solves each step to a looser tolerance than a gradient needs: the misses agree to far less
    // than a tolerance, not bit for bit.
    EXPECT_NEAR(sim["keyframe_errors"][k]["miss_after"].get<double>(),
                opt["keyframe_errors"][k]["miss_before"].get<double>(), 1e-3);
  }
}

TEST_F(SimulateMeasures, AFlockShapeReadsAsTheFractionInside) {
  write("flock.json", R"({"seed": 3, "time": {"fps": 30, "frames": 6},
    "flock": {"agents": 12, "spawn": {"radius": 3}},
    "objectives": [{"type": "shape", "frame": 6, "polygon": [[20, 20], [22, 20], [22, 22], [20, 22]]}]})");
  const auto r = run_keyframe("simulate flock.json --out run", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("\nshape@6: inside 0.000 (tolerance inside >= 0.95, not met)\n"), std::string::npos)
      << r.output;
  const Json report = Json::parse(read_text(dir_ / "run/report.json"));
  EXPECT_EQ(report["measures"][0]["inside_fraction"].get<double>(), 0.0);
}

TEST_F(SimulateMeasures, ASceneWithoutKeyframesPrintsNoneAndWritesEmptyLists) {
  write("cloth.json", R"({"time": {"frames": 2}, "cloth": {"nx": 3, "ny": 3, "pins": "top_edge"}})");
  const auto r = run_keyframe("simulate cloth.json --out run", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  const Json report = Json::parse(read_text(dir_ / "run/report.json"));
  EXPECT_TRUE(report["keyframe_errors"].empty());
}

TEST_F(SimulateMeasures, CsvExportRefusesABadRangeAnUnknownFormatAndAMissingRun) {
  write("cloth.json", kCloth);
  ASSERT_EQ(run_keyframe("simulate cloth.json --out run", dir_).code, 0);
  const auto range = run_keyframe("export run --format csv --frames 5:40", dir_);
  EXPECT_EQ(range.code, kExitInput) << range.output;
  EXPECT_NE(range.output.find("frames 5:40 out of range: run has frames 0..10"), std::string::npos) << range.output;
  EXPECT_FALSE(fs::exists(dir_ / "run/export/trajectory.csv"));
  const auto part = run_keyframe("export run --format csv --frames 3:5", dir_);
  ASSERT_EQ(part.code, 0) << part.output;
  EXPECT_EQ(csv_rows(dir_ / "run/export/trajectory.csv").size(), 1u + 2u * 25u);
  const auto unknown = run_keyframe("export run --format xls", dir_);
  EXPECT_EQ(unknown.code, kExitInput) << unknown.output;
  EXPECT_NE(unknown.output.find("unknown export format \"xls\" (expected one of: "), std::string::npos)
      << unknown.output;
  EXPECT_NE(unknown.output.find("|csv)"), std::string::npos) << unknown.output;
  const auto missing = run_keyframe("export nowhere --format csv", dir_);
  EXPECT_EQ(missing.code, kExitInput) << missing.output;
  EXPECT_EQ(missing.output, "keyframe: error: nowhere: not a run directory\n");
}

}  // namespace
}  // namespace kf

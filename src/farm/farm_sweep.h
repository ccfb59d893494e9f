#pragma once
// keyframe farm optimize: one `keyframe optimize` array task per scene and sweep point, each into its own run
// directory, then one dependent job that gathers their report.json files into a CSV and a plot.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farm/slurm.h"

namespace kf::farm {

// --sweep KEY=V1,V2,...: a JSON pointer into the scene file and the values it takes, each JSON (a word that
// is not JSON is a string). Commas inside [...], {...} or "..." do not split.
struct Sweep {
  std::string key;                    // "/cloth/stretch"
  std::vector<nlohmann::json> values;
  std::vector<std::string> texts;     // the values as written, for run names
};
// Throws InputError for a malformed --sweep.
Sweep parse_sweep(const std::string& text);

struct SweepRun {
  std::string name;       // "arch_stretch=500": the scene's name and the point's values
  std::string scene;      // the base scene's name
  nlohmann::json values;  // {"/cloth/stretch": 500, ...}
  nlohmann::json file;    // the scene file for this point (asset paths absolute)
};

// Every scene at every point of the sweeps' grid, each point's scene validated like `keyframe optimize`
// would (throws InputError naming the scene, the --sweep and the key; nothing written).
std::vector<SweepRun> plan_sweep(const std::vector<std::filesystem::path>& scenes, const std::vector<Sweep>& sweeps);

// True when RUN_DIR/report.json says the optimisation finished (not interrupted).
bool run_finished(const std::filesystem::path& run_dir);

struct SweepFarm {
  std::vector<SweepRun> runs;
  std::vector<std::string> keys;    // the sweeps' keys, in order
  std::filesystem::path out;        // absolute: scenes/, one directory per run, sweep.csv, farm/
  int max_evaluations = -1;         // passed to keyframe optimize when >= 0
  slurm::JobOptions slurm;
  std::filesystem::path keyframe;   // the keyframe program the jobs run
};

struct SweepPlan {
  std::vector<size_t> todo;         // indices into runs of those not finished yet, one array task each
  std::string optimize_script, gather_script;
};
SweepPlan plan_sweep_farm(const SweepFarm& farm);

// The manifest gather reads (OUT/sweep.json): keys and runs with their values.
nlohmann::json sweep_manifest(const SweepFarm& farm);

// Reads OUT/sweep.json and each run's report.json; writes OUT/sweep.csv (one row per run) and OUT/sweep.png.
// Returns the runs that have not finished (their rows say so).
std::vector<std::string> gather_sweep(const std::filesystem::path& out);

}  // namespace kf::farm

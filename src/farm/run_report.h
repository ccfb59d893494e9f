#pragma once
// What the farm reads back: a run's report.json (has it finished?) and a sweep's manifest (sweep.json),
// both validated like a scene: wrong types, non-finite numbers or names that would leave the sweep
// directory are InputError naming the file and the JSON pointer.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace kf::farm {

struct RunReport {
  bool interrupted = false;
  std::string status;
  double final_objective = 0;  // finite
  nlohmann::json json;         // the whole report
};

// RUN_DIR/report.json; nullopt when there is none. Throws InputError when it is not JSON, nests too deep,
// or "interrupted" (boolean), "status" (string), "final_objective" (finite number), "evaluations"
// (integer >= 0) or "wall_seconds" (number >= 0) are missing or of another type.
std::optional<RunReport> read_run_report(const std::filesystem::path& run_dir);

struct SweepManifest {
  struct Run {
    std::string name;       // a safe file name: the run's directory inside the sweep directory
    std::string scene;
    nlohmann::json values;  // {"/cloth/stretch": 500, ...}: one value per key
  };
  std::vector<std::string> keys;  // JSON pointers
  std::vector<Run> runs;
};

// OUT/sweep.json. Throws InputError naming the file and the JSON pointer of what is wrong.
SweepManifest read_sweep_manifest(const std::filesystem::path& out);

}  // namespace kf::farm

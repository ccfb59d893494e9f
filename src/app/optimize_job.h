#pragma once
// `keyframe optimize`: optimise a scene's controls and write the run directory.
#include <filesystem>
#include <string>

#include "core/error.h"  // kExitNotReached, kExitInterrupted: the exit codes these functions end with

namespace CLI {
class App;
}

namespace kf {

struct OptimizeOptions {
  std::string out;            // run directory ("" = out/<scene>/)
  int max_evaluations = -1;   // override the scene's limit (per stage) when >= 0
  bool quiet = false;         // no per-evaluation lines on stdout
  std::string resume;         // run directory to continue from (its scene.json and controls.bin)
  int checkpoint_every = -1;  // override the scene's optimizer.checkpoint_every when >= 0
  std::string max_memory;     // override the scene's optimizer.max_memory when not empty: a size ("4G", parse_memory_size)
  std::string adjoint;        // override the scene's optimizer.adjoint when not empty ("exact" | "swap")
  double max_seconds = -1;    // override the scene's optimizer.max_seconds (per stage) when >= 0
  int stop_when_reached = -1;  // override the scene's optimizer.stop_when_reached when 0 or 1 (a bench's)
};

struct OptimizeOutcome {
  std::filesystem::path dir;
  bool interrupted = false;
  bool failed = false;    // the keyframes were not reached (opt/diagnosis.h); the run directory is written
  std::string diagnosis;  // one line: what happened, its cause and what to change
};

// Throws InputError/OutputError. On SIGINT/SIGTERM it saves the best controls so far, writes the run
// directory and returns with interrupted = true.
OptimizeOutcome optimize_job(const std::filesystem::path& scene_file, const OptimizeOptions& options);

// The options `optimize` and `run` share (--out, --max-evaluations, --checkpoint-every, --max-memory, --adjoint,
// --quiet).
void add_optimize_options(CLI::App* sub, OptimizeOptions& o);
// Exits with kExitInterrupted when the job was stopped by a signal (after it saved its run directory).
void exit_if_interrupted(const OptimizeOutcome& r);
// Prints the diagnosis and exits with kExitNotReached when the keyframes were not reached.
void exit_if_failed(const OptimizeOutcome& r);

}  // namespace kf

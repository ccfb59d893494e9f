#pragma once
// What `optimize` writes after its strategy ran: controls.bin, schedule.bin, evaluations.bin, trajectory.bin,
// meshes.bin, iterations.csv, convergence.png and report.json, with the diagnosis (opt/diagnosis.h) of whether the
// keyframes were reached; and the keyframe judgement the strategy's stop rule asks.
#include <filesystem>

#include <nlohmann/json.hpp>

#include "app/evaluation_log.h"
#include "opt/diagnosis.h"
#include "opt/strategy.h"
#include "scene/scene.h"

namespace kf {

// A strategy's result with what the job adds to it.
struct OptimizeRun {
  StrategyResult strategy;
  double memory_budget_gb = 0;    // the run's budget
  int auto_checkpoint_every = 0;  // spacing the budget asked for in the last stage (0: none)
  Diagnosis diagnosis;
};

// Simulates the best point (and, for a cape blend, the uncontrolled run its end state is measured
// against), then writes the run's files into dir; sets run.diagnosis. Gives report.json's contents.
nlohmann::json write_run_report(const std::filesystem::path& dir, const Scene& scene, bool resuming, OptimizeRun& run,
                                const EvaluationLog& elog);

// Whether the problem's last rollout (every step kept) meets every keyframe's tolerance, judged as
// report.json judges the result, from the rollout's frames.
bool keyframes_met(const Scene& scene, Problem& problem);
// For each of scene.objectives, whether the problem's last rollout leaves it outside its tolerance.
std::vector<bool> keyframes_unmet(const Scene& scene, Problem& problem);

}  // namespace kf

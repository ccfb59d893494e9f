// keyframe simulate SCENE: the uncontrolled forward simulation, saved as a trajectory.
#include <chrono>
#include <iostream>
#include <string>

#include "adjoint/rollout.h"
#include "app/commands.h"
#include "app/body_meshes.h"
#include "app/memory_budget.h"
#include "app/run_dir.h"
#include "core/error.h"
#include "core/progress.h"
#include "core/trajectory.h"
#include "opt/diagnosis.h"
#include "report/figure_measures.h"
#include "report/keyframe_lines.h"
#include "sim/make_system.h"

namespace kf {
namespace fs = std::filesystem;

namespace {

// What simulate runs: the system as System::describe gives it, without the adjoint an optimisation of it
// would use, since simulate takes no gradient.
std::string forward_description(const System& sys) {
  std::string d = sys.describe();
  for (const std::string clause : {", exact adjoint", ", swap adjoint"})
    for (size_t at; (at = d.find(clause)) != std::string::npos;) d.erase(at, clause.size());
  return d;
}

}  // namespace

void add_simulate_command(CLI::App& app) {
  auto* sub = app.add_subcommand("simulate", "run the scene forward without controls and save the trajectory");
  auto scene_path = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  sub->add_option("SCENE", *scene_path, "scene file (JSON)")->required();
  auto max_memory = std::make_shared<std::string>();
  sub->add_option("--out", *out, "run directory (default: out/<scene>/)");
  sub->add_option("--max-memory", *max_memory,
                  "the memory the run may use, a size such as 4G, 512M or 1.5GiB (K, M, G, T are powers of "
                  "1024; a plain number is bytes; 0 = the default, the machine's memory), as `optimize` takes "
                  "it: a run estimated to need more is refused up front");
  sub->callback([=] {
    Scene scene = load_scene(*scene_path);
    if (scene.cloth) scene.cloth->use_motion_tolerance();
    // Before the system is built: a run too large to hold is refused at once.
    check_memory(scene, simulate_memory(scene), max_memory->empty() ? 0 : parse_memory_size(*max_memory));
    auto sys = make_system(scene);
    const auto dir = run_dir_for(scene, *out);
    StagedDir staged(dir);  // locks an existing run directory before the work starts
    VecX x0, v0;
    sys->initial_state(x0, v0);
    Rollout r;
    const auto t0 = std::chrono::steady_clock::now();
    const bool ok = simulate_frames(*sys, x0, v0, scene.time, r);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!ok) {
      const std::string why = sys->divergence_reason();
      throw InputError(scene.file.string() + ": the simulation diverged at step " + std::to_string(r.diverged_at) +
                       (why.empty() ? " (reduce the time step or the stiffness)" : ": " + why));
    }
    const Trajectory frames = frames_of(r, scene.time, sys->particles());
    // The dry run's measures: how far the uncontrolled motion misses each keyframe, judged as optimize
    // judges its result, so a keyframe can be weighed before a long optimisation.
    const std::vector<KeyframeMeasure> keyframe_measures = measure_keyframes(scene, frames);
    const nlohmann::json measures = figure_measures(scene, frames, keyframe_measures);
    const std::vector<KeyframeJudgement> keyframes = judge_keyframes(scene, keyframe_measures, keyframe_measures);
    commit_run_dir(staged, [&](const fs::path& work) {
      prepare_run_dir(work, scene);
      save_trajectory(work / "trajectory.bin", frames);
      write_body_meshes(scene, scene.time.frames + 1, work / "meshes.bin");
      nlohmann::json report = {{"scene", scene.name}, {"command", "simulate"}, {"system", forward_description(*sys)},
                               {"gradient", false},
                               {"steps", scene.time.steps()}, {"frames", scene.time.frames + 1},
                               {"simulate_seconds", secs}};
      for (const auto& [name, value] : sys->run_stats()) report["run_stats"][name] = value;
      report["measures"] = measures;
      report["keyframe_errors"] = nlohmann::json::array();
      for (const auto& k : keyframes) report["keyframe_errors"].push_back(k.to_json());
      write_json(work / "report.json", report);
    });
    std::cout << "simulated " << scene.time.steps() << " steps forward (no controls, no gradient) of "
              << forward_description(*sys) << " in " << secs
              << " s -> " << (dir / "trajectory.bin").string() << "\n";
    for (const std::string& line : keyframe_lines(scene, keyframes)) std::cout << line << "\n";
  });
}

}  // namespace kf

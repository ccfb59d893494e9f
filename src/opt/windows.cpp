#include "opt/windows.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "opt/throw_search.h"
#include "sim/make_system.h"

namespace kf {

namespace {

// The latest frame any keyframe reads (the scene's last frame when there are none).
int last_keyframe(const Scene& scene) {
  int last = 0;
  for (const auto& o : scene.objectives) last = std::max(last, o.frame);
  return scene.objectives.empty() ? scene.time.frames : std::min(last, scene.time.frames);
}

}  // namespace

// Windows grown backwards from the last keyframe. The first (shortest) window gets half the budget, the
// others share the rest equally: its gradient is the only tame one, so it does most of the work and is still
// descending at an equal share, while longer windows mostly stall within a few evaluations and pass their
// unspent budget on. Per-frame forces act on the 3 x 3 lattice in every window, then per particle over the
// last (the whole) window.
std::vector<StageSpec> window_stages(const Scene& scene, int budget) {
  const OptimizerSpec& o = scene.optimizer;
  const ControlSpec& c = scene.controls;
  const bool lattice = c.kind == ControlKind::kPerFrame;
  const int last = last_keyframe(scene);
  std::vector<int> starts;  // latest first: K - w, K - 2w, K - 4w, ... above from_frame, then from_frame
  for (long w = o.window_frames; last - w > c.from_frame; w *= 2) starts.push_back(int(last - w));
  starts.push_back(c.from_frame);
  const int windows = int(starts.size()), n = windows + (lattice ? 1 : 0);
  const int first = n > 1 ? std::max(1, budget / 2) : budget;
  const int part = n > 1 ? std::max(1, (budget - first) / (n - 1)) : 0;
  std::vector<StageSpec> stages;
  for (int k = 0; k < n; ++k) {
    const int share = k == 0 ? first : k + 1 < n ? part : std::max(1, budget - first - part * (n - 2));
    StageSpec s{scene.time.substeps, share, std::nullopt};
    if (k + 1 < n) {
      ControlSpec window = c;
      window.from_frame = starts[k];
      if (lattice) window.kind = ControlKind::kPerFrameLattice;
      s.controls = window;
    }
    stages.push_back(s);
  }
  return stages;
}

namespace {

std::string describe(const std::vector<StageSpec>& stages, int scene_from) {
  std::ostringstream os;
  const bool lattice = stages.front().controls && stages.front().controls->kind == ControlKind::kPerFrameLattice;
  for (size_t k = 0; k + (lattice ? 1 : 0) < stages.size(); ++k)
    os << (k ? ", " : "") << (stages[k].controls ? stages[k].controls->from_frame : scene_from);
  return os.str();
}

}  // namespace

double gradient_growth(Problem& problem, const VecX& z, int reference) {
  const Controls& c = problem.controls();
  const ControlKind kind = c.kind();
  VecX g(problem.size());
  problem.evaluate(z, &g);
  if (problem.last_diverged() || (kind != ControlKind::kPerStep && kind != ControlKind::kPerFrame)) return 0;
  const bool per_frame = kind == ControlKind::kPerFrame;
  const int substeps = problem.time().substeps, frames = problem.time().frames, first = c.first_frame();
  const long stride = per_frame ? g.size() / std::max(1, frames - first)
                                : g.size() / std::max(1, (frames - first) * substeps);
  std::vector<double> sq(frames, 0.0);  // squared gradient norm of each frame's forces
  for (long b = 0; b * stride < g.size(); ++b) {
    const int frame = first + int(per_frame ? b : b / substeps);
    sq[std::min(frame, frames - 1)] += g.segment(b * stride, stride).squaredNorm();
  }
  const double largest = std::sqrt(*std::max_element(sq.begin(), sq.end()));
  const double ref = std::sqrt(sq[std::clamp(reference, 0, frames - 1)]);
  if (largest == 0) return 1;
  return ref > 0 ? largest / ref : std::numeric_limits<double>::infinity();
}

StagePlan plan_stages(const Scene& scene) {
  const OptimizerSpec& o = scene.optimizer;
  StagePlan plan;
  if (!o.schedule.empty()) {
    plan.stages = o.schedule;
    plan.why = "stages: the scene's schedule";
    return plan;
  }
  plan.stages = {{scene.time.substeps, o.max_evaluations, std::nullopt}};  // the whole horizon at once
  plan.scaled_first_step = scene.flock.has_value();
  if (o.strategy == StagingStrategy::kSingle || !scene.cloth || o.max_evaluations < 2) return plan;
  const ControlSpec& c = scene.controls;
  if (c.kind == ControlKind::kInitialVelocity) {
    ControlSpec rigid = c;
    rigid.kind = ControlKind::kInitialRigidVelocity;
    const int rigid_budget = std::clamp(o.max_evaluations / 3, 1, 40);
    ControlSpec lattice = c;
    lattice.kind = ControlKind::kInitialLatticeVelocity;
    const int lattice_budget = std::clamp((o.max_evaluations - rigid_budget) / 3, 0, 60);
    plan.stages = {{scene.time.substeps, rigid_budget, rigid}};
    if (lattice_budget > 0) plan.stages.push_back({scene.time.substeps, lattice_budget, lattice});
    plan.stages.push_back({scene.time.substeps, o.max_evaluations - rigid_budget - lattice_budget, std::nullopt});
    plan.throw_search = o.throw_search >= 0 ? o.throw_search
                                            : automatic_throw_count(scene.cloth->particles(), scene.time.steps());
    plan.why = "stages: a search over " + std::to_string(plan.throw_search) +
               " rigid throws, the best rigid throw (6 variables), a 3 x 3 lattice of initial velocities over the "
               "sheet from it, then one initial velocity per particle";
    plan.scaled_first_step = true;
    return plan;
  }
  if (c.kind != ControlKind::kPerStep && c.kind != ControlKind::kPerFrame) return plan;
  const int last = last_keyframe(scene);
  if (last - o.window_frames <= c.from_frame) return plan;  // the whole horizon is one window already
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  plan.growth = gradient_growth(problem, problem.initial_guess(), last - 1);
  std::ostringstream os;
  os.precision(2);
  os << "force gradient at the start grows " << plan.growth << "x from frame " << last - 1 << " back to frame "
     << c.from_frame;
  // Per-frame forces on a sheet that meets colliders or a body get windows whatever the growth at the start:
  // the contact that makes a per-particle gradient rough may begin only later (a towel sliding off its rail).
  const bool contact = c.kind == ControlKind::kPerFrame && (!scene.cloth->colliders.empty() || scene.character);
  if (plan.growth > o.window_growth || contact) {
    plan.stages = window_stages(scene, o.max_evaluations);
    plan.scaled_first_step = true;
    if (plan.growth > o.window_growth) os << " (above optimizer.window_growth " << o.window_growth << ")";
    else os << " (the sheet meets colliders or a body)";
    os << ": windows from frames "
       << describe(plan.stages, c.from_frame) << " to frame " << last;
    if (c.kind == ControlKind::kPerFrame)
      os << ", each on a 3 x 3 lattice of forces over the sheet, then one force per particle from frame " << c.from_frame;
  } else {
    os << " (not above optimizer.window_growth " << o.window_growth
       << "): one stage, then windows from no force if it ends early with evaluations left";
    plan.windows_on_early_end = true;
  }
  plan.why = os.str();
  return plan;
}

}  // namespace kf

#include "opt/windows.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "opt/friction_continuation.h"
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

// The eased windows get this share of the budget, the windows at the scene's friction the rest.
constexpr double kEasedShare = 0.4;

void ease_friction(const Scene& scene, double scale, StagePlan& plan) {
  if (plan.stages.size() < 2 || !has_friction(scene) || scale >= 1) return;
  const int budget = scene.optimizer.max_evaluations;
  const int eased = int(budget * kEasedShare);
  std::vector<int> eased_until, until;
  std::vector<StageSpec> stages = window_stages(scene, eased, &eased_until);
  const std::vector<StageSpec> full = window_stages(scene, budget - eased, &until);
  plan.friction_scales.assign(stages.size(), scale);
  plan.friction_scales.resize(stages.size() + full.size(), 1.0);
  stages.insert(stages.end(), full.begin(), full.end());
  eased_until.insert(eased_until.end(), until.begin(), until.end());
  plan.stages = std::move(stages);
  plan.judged_until = std::move(eased_until);
  std::ostringstream os;
  os << "; friction eased in: these stages first with friction scaled by " << scale << " (" << eased
     << " evaluations), then again at the scene's friction";
  plan.why += os.str();
}

std::vector<int> keyframe_frames(const Scene& scene) {
  std::vector<int> frames;
  for (const auto& o : scene.objectives)
    if (o.frame > scene.controls.from_frame && o.frame <= scene.time.frames) frames.push_back(o.frame);
  std::sort(frames.begin(), frames.end());
  frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  return frames;
}

namespace {

// A stage with fewer evaluations than this rarely gets past its line search's first trials.
constexpr int kMinStageEvaluations = 12;

struct Window {
  int start;         // its first controlled frame
  int until;         // the frame its keyframes count up to (kAllKeyframes: all)
  bool lead;         // the first (shortest) window of its keyframe: the tame gradient, the larger share
  bool bottom;       // the one reaching down to where its keyframe's windows end
  bool per_particle; // the scene's own forces (not the lattice) over its keyframe's first window's frames
};

// Windows grown backwards from the keyframe at `frame` down to `lower`: frame - w, frame - 2w, ... above
// lower, then lower. With `per_particle`, then the scene's own forces over the first window's frames.
void grow_back(std::vector<Window>& out, int frame, int lower, int window_frames, int until, bool per_particle) {
  bool lead = true;
  for (long w = window_frames; frame - w > lower; w *= 2, lead = false)
    out.push_back({int(frame - w), until, lead, false, false});
  out.push_back({lower, until, lead, true, false});
  if (per_particle) out.push_back({std::max(lower, frame - window_frames), until, false, false, true});
}

// The windows in time order: each keyframe's grown back from it, the earliest's to controls.from_frame and
// each later one's to the keyframe before it, only keyframes up to its own counting (the last: all). Lattice
// windows end with a per-particle window over their keyframe's first window's frames.
std::vector<Window> plan_windows(const Scene& scene, bool lattice) {
  const ControlSpec& c = scene.controls;
  const std::vector<int> frames = keyframe_frames(scene);
  std::vector<Window> windows;
  if (frames.size() < 2) {
    grow_back(windows, last_keyframe(scene), c.from_frame, scene.optimizer.window_frames, kAllKeyframes, lattice);
    return windows;
  }
  int lower = c.from_frame;
  for (size_t k = 0; k < frames.size(); ++k) {
    grow_back(windows, frames[k], lower, scene.optimizer.window_frames,
              k + 1 < frames.size() ? frames[k] : kAllKeyframes, lattice);
    lower = frames[k];
  }
  return windows;
}

}  // namespace

// The first (shortest) window of a keyframe gets the larger share: its gradient is the only tame one, so it
// does most of the work and is still descending at an equal share, while longer windows mostly stall within
// a few evaluations and pass their unspent budget on. Per-frame forces act on the 3 x 3 lattice in every
// window; after a keyframe's lattice windows its forces act per particle over that keyframe's first window
// (the forces before it held), where a per-particle gradient is still tame, and, after every keyframe's, per
// particle over the whole horizon. A later lattice window would fit a per-particle window's forces back onto
// the lattice, so the per-particle window comes after its keyframe's lattice windows, not after the first.
// With keyframes at several frames a last stage of the scene's own controls over the whole horizon follows
// the windows.
std::vector<StageSpec> window_stages(const Scene& scene, int budget, std::vector<int>* judged_until) {
  const ControlSpec& c = scene.controls;
  const bool lattice = c.kind == ControlKind::kPerFrame;
  std::vector<Window> windows = plan_windows(scene, lattice);
  const bool ordered = keyframe_frames(scene).size() > 1;
  const int extra = lattice || ordered ? 1 : 0;  // the last stage over the whole horizon, when it is not a window
  const auto too_many = [&] { return int(windows.size() + extra) * kMinStageEvaluations > budget; };
  // A budget below what every window needs plans fewer windows, rather than each cut short: the middle
  // windows of each keyframe go first, the longest before the shorter; then the per-particle windows. Each
  // keyframe keeps its first window and the one reaching down to where its windows end.
  for (size_t k = windows.size(); k-- > 0 && too_many();)
    if (!windows[k].lead && !windows[k].bottom && !windows[k].per_particle) windows.erase(windows.begin() + long(k));
  if (too_many())
    windows.erase(std::remove_if(windows.begin(), windows.end(), [](const Window& w) { return w.per_particle; }),
                  windows.end());
  // The last window of a single keyframe, when it is not on the lattice, is the scene's own controls.
  const int n = int(windows.size()) + extra;
  int leads = 0;
  for (const Window& w : windows) leads += w.lead;
  const int lead_share = n > 1 ? std::max(1, budget / 2 / std::max(1, leads)) : budget;
  const int others = n - leads;
  const int part = others > 0 ? std::max(1, (budget - lead_share * leads) / others) : 0;
  std::vector<StageSpec> stages;
  if (judged_until) judged_until->clear();
  int given = 0;
  for (int k = 0; k < n; ++k) {
    const bool lead = k < int(windows.size()) && windows[k].lead;
    const int share = k + 1 < n ? (lead ? lead_share : part) : std::max(1, budget - given);
    given += share;
    StageSpec s{scene.time.substeps, share, std::nullopt};
    if (k + 1 < n) {
      ControlSpec window = c;
      window.from_frame = windows[k].start;
      if (lattice && !windows[k].per_particle) window.kind = ControlKind::kPerFrameLattice;
      s.controls = window;
    }
    stages.push_back(s);
    if (judged_until) judged_until->push_back(k < int(windows.size()) ? windows[k].until : kAllKeyframes);
  }
  return stages;
}

namespace {

// "windows from frames 23, 18, 8, 0 to frame 28", or in keyframe order "windows to frame 12 from frames 7,
// 2, 0, then to frame 28 (every keyframe) from frames 23, 18, 12"; a per-particle window after a keyframe's
// lattice windows as ", then per particle from frame 7".
std::string describe(const std::vector<StageSpec>& stages, const std::vector<int>& until, int last, int scene_from) {
  std::ostringstream os;
  const bool ordered = std::find(until.begin(), until.end(), kAllKeyframes) != until.begin();
  const bool lattice = stages.front().controls && stages.front().controls->kind == ControlKind::kPerFrameLattice;
  const size_t windows = ordered || lattice ? stages.size() - 1 : stages.size();
  os << "windows";
  for (size_t k = 0; k < windows; ++k) {
    const int from = stages[k].controls ? stages[k].controls->from_frame : scene_from;
    const bool per_particle =
        lattice && stages[k].controls && stages[k].controls->kind != ControlKind::kPerFrameLattice;
    const bool group_start = k == 0 || until[k] != until[k - 1];
    if (per_particle) {
      if (!ordered) os << " to frame " << last;
      os << ", then per particle from frame " << from;
      continue;
    }
    if (ordered && group_start)
      os << (k ? ", then" : "") << " to frame " << (until[k] == kAllKeyframes ? last : until[k])
         << (until[k] == kAllKeyframes ? " (every keyframe)" : "") << " from frames ";
    else if (!ordered && k == 0) os << " from frames ";
    else os << ", ";
    os << from;
  }
  const bool ends_per_particle = windows > 0 && lattice && stages[windows - 1].controls &&
                                 stages[windows - 1].controls->kind != ControlKind::kPerFrameLattice;
  if (!ordered && !ends_per_particle) os << " to frame " << last;
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

namespace {

// Initial velocities: a search over rigid throws, the best rigid throw, a 3 x 3 lattice from it, then one
// velocity per particle. A large sheet's stages share fewer evaluations, large_flight_share to the power
// 1.5: each of its evaluations costs several small sheets' (more particle-steps, and more conjugate-gradient
// iterations a step as the sheet grows), and where its throw search and rigid fit leave it the stages
// after them rarely gain.
void plan_throw(const Scene& scene, StagePlan& plan) {
  const OptimizerSpec& o = scene.optimizer;
  const ControlSpec& c = scene.controls;
  const double share = std::pow(large_flight_share(scene.cloth->particles(), scene.time.steps()), 1.5);
  // Never below what three stages need to get past their line searches' first trials.
  const int budget = std::max(std::min(o.max_evaluations, 3 * kMinStageEvaluations),
                              int(std::lround(o.max_evaluations * share)));
  ControlSpec rigid = c;
  rigid.kind = ControlKind::kInitialRigidVelocity;
  const int rigid_budget = std::clamp(budget / 3, 1, 40);
  ControlSpec lattice = c;
  lattice.kind = ControlKind::kInitialLatticeVelocity;
  const int lattice_budget = std::clamp((budget - rigid_budget) / 3, 0, 60);
  plan.stages = {{scene.time.substeps, rigid_budget, rigid}};
  if (lattice_budget > 0) plan.stages.push_back({scene.time.substeps, lattice_budget, lattice});
  plan.stages.push_back({scene.time.substeps, budget - rigid_budget - lattice_budget, std::nullopt});
  // The automatic search spends at most twice the budget in throws (each a simulation without its adjoint
  // pass): a budget the user cut cuts the search too.
  plan.throw_search = o.throw_search >= 0 ? o.throw_search
                                          : std::min(automatic_throw_count(scene.cloth->particles(), scene.time.steps()),
                                                     2 * o.max_evaluations);
  plan.why = "stages: a search over " + std::to_string(plan.throw_search) +
             " rigid throws, the best rigid throw (6 variables), a 3 x 3 lattice of initial velocities over the "
             "sheet from it, then one initial velocity per particle";
  if (budget < o.max_evaluations) {
    plan.scaled_budget = budget;
    plan.why += " (" + std::to_string(budget) + " of the " + std::to_string(o.max_evaluations) +
                " evaluations: a flight of " + std::to_string(scene.cloth->particles() * scene.time.steps()) +
                " particle-steps)";
  }
  plan.scaled_first_step = true;
}

}  // namespace

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
    plan_throw(scene, plan);
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
    plan.stages = window_stages(scene, o.max_evaluations, &plan.judged_until);
    plan.scaled_first_step = true;
    plan.uniform_push = o.uniform_push;
    if (plan.growth > o.window_growth) os << " (above optimizer.window_growth " << o.window_growth << ")";
    else os << " (the sheet meets colliders or a body)";
    os << ": " << describe(plan.stages, plan.judged_until, last, c.from_frame);
    if (c.kind == ControlKind::kPerFrame)
      os << " (all but the per-particle ones on a 3 x 3 lattice of forces over the sheet), then one force per particle "
            "from frame " << c.from_frame;
    else if (keyframe_frames(scene).size() > 1)
      os << ", then the scene's forces from frame " << c.from_frame;
    if (plan.uniform_push) os << "; the first window starts from the uniform push that best places the keyframes";
  } else {
    os << " (not above optimizer.window_growth " << o.window_growth
       << "): one stage, then windows from no force if it ends early with evaluations left";
    plan.windows_on_early_end = true;
  }
  plan.why = os.str();
  return plan;
}

}  // namespace kf

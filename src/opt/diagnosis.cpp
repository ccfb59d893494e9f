#include "opt/diagnosis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/check.h"
#include "opt/gradcheck.h"
#include "opt/problem.h"
#include "sim/make_system.h"

namespace kf {

namespace {

// A budget this small says nothing about whether more evaluations would reach the keyframes.
constexpr int kFewEvaluations = 50;
// The effort's share of the objective below which neither a keyframe's weight nor controls.alpha decides where
// the run ends.
constexpr double kNegligibleEffort = 0.01;
// More evaluations than this many times those run, at the run's own rate: a budget the user will not give.
constexpr double kHopelessBudgetRatio = 10;

std::string format(const char* fmt, double a, double b = 0) {
  char buf[1024];
  std::snprintf(buf, sizeof buf, fmt, a, b);
  return buf;
}

}  // namespace

nlohmann::json KeyframeJudgement::to_json() const {
  nlohmann::json j = {{"name", name},
                      {"frame", frame},
                      {"judged", judged},
                      {"error_before", error_before},
                      {"error_after", error_after},
                      {"met", met()}};
  if (judged) {
    j["tolerance"] = tolerance;
    j["miss_before"] = miss_before;
    j["miss_after"] = miss_after;
  }
  return j;
}

std::vector<KeyframeJudgement> judge_keyframes(const Scene& scene, const std::vector<KeyframeMeasure>& before,
                                               const std::vector<KeyframeMeasure>& after) {
  CHECK_EQ(before.size(), scene.objectives.size());
  CHECK_EQ(after.size(), scene.objectives.size());
  std::vector<KeyframeJudgement> out;
  for (size_t i = 0; i < scene.objectives.size(); ++i) {
    const ObjectiveSpec& o = scene.objectives[i];
    KeyframeJudgement k;
    k.name = std::string(type_name(o)) + "@" + std::to_string(o.frame);
    k.frame = o.frame;
    k.judged = after[i].judged;
    k.miss_before = before[i].miss;
    k.miss_after = after[i].miss;
    k.error_before = before[i].error;
    k.error_after = after[i].error;
    k.tolerance = after[i].tolerance;
    k.error_phrase = after[i].error_phrase;
    k.from_target = after[i].from_target;
    out.push_back(std::move(k));
  }
  return out;
}

std::vector<bool> keyframes_unmet(const Scene& scene, const Trajectory& frames) {
  const std::vector<KeyframeMeasure> m = measure_keyframes(scene, frames);
  std::vector<bool> unmet;
  for (const KeyframeJudgement& k : judge_keyframes(scene, m, m)) unmet.push_back(!k.met());
  return unmet;
}

nlohmann::json Sensitivity::to_json() const {
  return {{"keyframe", keyframe},
          {"gradient_by_frame", gradient_by_frame},
          {"gradient_growth", growth},
          {"gradient_growth_beyond_free_flight", growth_beyond_free},
          {"gradient_grows_from_frame", grows_from_frame},
          {"objective_start", phi},
          {"objective_noise_start", phi_noise},
          {"objective_relative_noise_start", relative_noise()}};
}

Sensitivity measure_sensitivity(const Scene& scene, const TimeSpec& time, int checkpoint_every,
                                std::size_t memory_budget) {
  Sensitivity s;
  for (const auto& o : scene.objectives) s.keyframe = std::max(s.keyframe, o.frame);
  Scene probe = scene;
  probe.controls.kind = ControlKind::kPerFrame;
  probe.controls.from_frame = 0;
  const auto sys = make_system(probe, time.h());
  Problem problem(probe, time, *sys);
  if (checkpoint_every > 0) problem.set_checkpoint_every(checkpoint_every);
  problem.set_memory_budget(memory_budget);
  const VecX z = problem.initial_guess();
  VecX g;
  s.phi = problem.evaluate(z, &g);
  if (problem.last_diverged()) return s;
  s.phi_noise = phi_noise(problem, z, s.phi, 11);
  VecX u;
  for (int f = 0; f < s.keyframe; ++f) {
    problem.controls().force_at(g, f * time.substeps, u);
    s.gradient_by_frame.push_back(u.norm());
  }
  if (s.gradient_by_frame.empty()) return s;
  const int k = s.keyframe;
  const double last = s.gradient_by_frame.back(), most = *std::max_element(s.gradient_by_frame.begin(),
                                                                          s.gradient_by_frame.end());
  if (!(last > 0)) return s;  // the keyframes do not depend on the last frame's force (a shape met already)
  s.growth = most / last;
  s.growth_beyond_free = 0;
  for (int f = 0; f < k; ++f) s.growth_beyond_free = std::max(s.growth_beyond_free, s.gradient_by_frame[f] / (last * (k - f)));
  for (int f = 0; f < k; ++f)
    if (s.gradient_by_frame[f] >= 0.1 * most) s.grows_from_frame = f;
  return s;
}

DescentProbe probe_descent(Problem& problem, const VecX& z) {
  DescentProbe p;
  VecX g(problem.size());
  p.phi = problem.evaluate(z, &g);
  p.grad_norm = g.norm();
  if (problem.last_diverged() || !(p.grad_norm > 0) || !(p.phi > 0)) return p;
  const double reach = p.phi / p.grad_norm;
  const VecX dir = g / p.grad_norm;
  p.linear_fraction = 0;
  bool linear = true;
  for (int k = 0; k <= 12; ++k) {
    const double fraction = std::pow(10.0, -6.0 + 0.5 * k), t = fraction * reach;
    const double phi = problem.evaluate(z - t * dir, nullptr);
    p.steps.push_back(t);
    p.phis.push_back(phi);
    linear = linear && !problem.last_diverged() && phi <= p.phi - 0.5 * t * p.grad_norm;
    if (linear) p.linear_fraction = fraction;
  }
  return p;
}

nlohmann::json DescentProbe::to_json() const {
  return {{"phi", phi}, {"grad_norm", grad_norm}, {"linear_fraction", linear_fraction}, {"steps", steps},
          {"phi_along_descent", phis}};
}

nlohmann::json Diagnosis::to_json() const {
  return {{"outcome", outcome}, {"reached", reached}, {"progress", progress}, {"far", far}, {"failed", failed()},
          {"diagnosis", line}};
}

namespace {

// The judged keyframe that missed by most, or null when none was judged.
const KeyframeJudgement* worst_keyframe(const std::vector<KeyframeJudgement>& keyframes) {
  const KeyframeJudgement* worst = nullptr;
  for (const auto& k : keyframes)
    if (k.judged && (!worst || k.miss_after > worst->miss_after)) worst = &k;
  return worst;
}

// Where the worst keyframe ended against its target.
std::string miss_text(const KeyframeJudgement& worst) {
  if (!worst.from_target)
    return worst.name + " ends at " + worst.error_after + " (needs " + worst.tolerance + "; " + worst.error_before +
           " uncontrolled)";
  return worst.name + " is " + worst.error_after + " from its target (tolerance " + worst.tolerance + "; " +
         worst.error_before + " uncontrolled)";
}

std::string verdict_head(const Diagnosis& d, const RunFacts& facts) {
  std::string head = !d.progress ? "no progress: "
                     : d.far      ? "keyframes not reached: "
                                  : "keyframes not reached, but near: ";
  if (!d.progress)
    head += format("the keyframe terms went from %.3g to %.3g; ", facts.keyframe_objective_start,
                   facts.keyframe_objective_end);
  return head;
}

// A flock's agents packed within each other's avoidance radius: the stiffness of hundreds of neighbours
// brings the explicit step near its stability limit, and every small change moves neighbours across the
// kernels' radii.
constexpr const char* kPackedAgents = "agents packed within each other's avoidance radius";
constexpr const char* kSpreadAgents =
    "fewer agents per area (larger shapes or a larger spawn disc), the shape's coverage term so the agents "
    "spread, finer time steps (time.substeps) or more drag (flock.drag.strength)";

std::string amplifying_cause(const Sensitivity& s, const RunFacts& facts) {
  std::string cause = format("cause: the motion amplifies perturbations: the gradient per frame grows %.2gx from the "
                             "keyframe back to frame %.0f (",
                             s.growth, s.grows_from_frame) +
                      (facts.flock ? std::string(kPackedAgents) + " after it); change: " + kSpreadAgents
                                   : std::string("folds, sliding or buckling in contact after it); change: steer over a "
                                                 "window after that frame (controls.from_frame), keyframe earlier, or "
                                                 "damp the motion (cloth.damping, cloth.air_drag, friction)"));
  if (facts.max_objective > 1e6 * std::max(facts.objective_start, 1e-300))
    cause += format("; trial steps reached an objective of %.2g from %.2g", facts.max_objective, facts.objective_start);
  return cause;
}

// Smooth dynamics and no budget to blame: either the effort outweighs the rest or the target is out of reach.
std::string smooth_cause(const Sensitivity& s, const RunFacts& facts) {
  const double phi = facts.keyframe_objective_end + facts.effort_end;
  const double effort_share = phi > 0 ? facts.effort_end / phi : 0.0;
  if (effort_share > 0.5)
    return format("cause: the control effort is %.0f %% of the objective: what is left of the keyframe terms "
                  "costs less than the force that would remove it; change: raise the keyframe's weight or lower "
                  "controls.alpha",
                  100 * effort_share);
  if (facts.budget) {  // stalled before its budget ended: nothing measured says the target is out of reach
    const std::string head =
        format("cause: the dynamics are smooth (the gradient grows %.2gx over the horizon) and the objective had "
               "stopped falling (%.2gx over the last tenth of the evaluations) when its budget ended (",
               s.growth, 1 / std::max(facts.recent_improvement, 1e-300)) +
        facts.status + format("), with the effort %.0f %% of the objective", 100 * effort_share);
    // Effort this small holds nothing back: a heavier keyframe or a lower alpha moves the same minimum.
    if (effort_share < kNegligibleEffort)
      return head + ", so neither the keyframe's weight nor controls.alpha holds it back: the run is in a basin "
                    "whose lowest point misses the keyframe (a landing or a contact its gradient does not see "
                    "past); change: keyframe before the contact, controls that act longer (controls.from_frame, "
                    "or forces rather than an initial velocity), or move the keyframe";
    return head + "; change: raise the keyframe's weight, give the controls more time (controls.from_frame) or "
                  "lower controls.alpha";
  }
  return format("cause: the dynamics are smooth (the gradient grows %.2gx over the horizon) and the "
                "optimiser stopped (",
                s.growth) +
         facts.status +
         format("), so the target is likely out of reach: inside or behind a collider, or costing more "
                "force than controls.alpha allows (the effort is %.0f %% of the objective); change: move the "
                "keyframe, give the controls more time, or lower controls.alpha",
                100 * effort_share);
}

// Trial steps the system refused as unstable, often enough that the search crept along their edge.
bool unstable_edge(const RunFacts& facts) {
  return facts.unstable_trials >= 3 && 4 * facts.unstable_trials >= facts.evaluations;
}

std::string unstable_cause(const RunFacts& facts) {
  return format("cause: %.0f of its %.0f evaluations were trial steps whose simulation was refused as unstable ",
                double(facts.unstable_trials), double(facts.evaluations)) +
         (facts.flock ? "(agents packed so densely that the explicit step overshoots their velocity matching), so "
                        "the search crept along that edge; change: flock.step \"implicit_damping\" (stable however "
                        "densely they pack), finer time steps (time.substeps), a later keyframe so the agents need not "
                        "rush, or a lower flock.matching.strength"
                      : "(its step cannot follow the state they reach), so the search crept along that edge; change: "
                        "finer time steps (time.substeps)");
}

// Every trial step after the start diverged: the run never left its start, and nothing it measured says
// anything of the target's reach.
bool every_trial_diverged(const RunFacts& facts) {
  return facts.evaluations >= 2 && facts.diverged_trials >= facts.evaluations - 1;
}

std::string diverged_cause(const RunFacts& facts) {
  return format("cause: every trial step's simulation diverged (%.0f of its %.0f evaluations), so the run never "
                "left its start; change: ",
                double(facts.diverged_trials), double(facts.evaluations)) +
         (facts.flock ? "finer time steps (time.substeps), flock.step \"implicit_damping\", a smaller "
                        "optimizer.first_step or a later keyframe"
                      : "finer time steps (time.substeps), a smaller optimizer.first_step or a later keyframe");
}

// A keyframe the run left where the uncontrolled motion had it (within 10 % of its miss) while another
// keyframe was met: measured by the two judgements, so it comes before any guessed cause.
std::string untouched_cause(const std::vector<KeyframeJudgement>& keyframes) {
  const KeyframeJudgement *untouched = nullptr, *met = nullptr;
  for (const auto& k : keyframes) {
    if (!k.judged) continue;
    if (k.miss_after <= 1.0 && k.miss_before > 1.0 && !met) met = &k;
    if (k.miss_after > 1.0 && k.miss_after >= 0.9 * k.miss_before &&
        (!untouched || k.miss_after > untouched->miss_after))
      untouched = &k;
  }
  if (!untouched || !met) return {};
  return "cause: " + untouched->name + " was left at its uncontrolled error (" + untouched->error_after + ", " +
         untouched->error_before + " uncontrolled) while " + met->name + " was met (" + met->error_before + " → " +
         met->error_after + "): the optimiser steered the other keyframe, not this one" +
         (untouched->frame < met->frame ? " (an earlier keyframe)" : "") +
         "; change: raise " + untouched->name + "'s weight, or keyframe it in a scene cut at its frame first";
}

}  // namespace

int expected_more_evaluations(const RunFacts& facts, double worst_miss) {
  if (!(facts.recent_improvement < 1.0) || !(facts.recent_improvement > 0.0) || !(worst_miss > 1.0)) return 0;
  const double tenth = std::max(1.0, facts.evaluations / 10.0);
  const double tenths = std::log(worst_miss * worst_miss) / std::log(1.0 / facts.recent_improvement);
  return int(std::ceil(std::min(tenth * tenths, 1e9)));
}

namespace {

// A budget stop whose cause is another (amplification, roughness, noise) still says what its own progress
// expects of more evaluations: a user deciding whether to raise optimizer.max_evaluations needs that whatever
// the cause. Nothing when the best objective did not fall over the last tenth: that tenth may begin in a stage
// whose objective is not comparable (raised keyframe weights, another control kind's effort), so it says
// nothing of the last stage's own progress.
std::string budget_expectation(const RunFacts& facts, double worst_miss) {
  const int more = expected_more_evaluations(facts, worst_miss);
  const std::string over = format("the last tenth of its %.0f evaluations", facts.evaluations);
  if (more > 0)
    return "; at the rate the objective fell over " + over +
           format(" (%.2gx), the worst keyframe needs about %.0f more evaluations to come within its tolerance",
                  1 / std::max(facts.recent_improvement, 1e-300), double(more)) +
           (more > kHopelessBudgetRatio * facts.evaluations ? " (more evaluations are not the remedy)" : "");
  if (facts.evaluations < kFewEvaluations)
    return "; the objective did not fall over " + over + ", too few evaluations to tell how many more it needs";
  return {};
}

std::string budget_cause(const RunFacts& facts, double worst_miss) {
  const int more = expected_more_evaluations(facts, worst_miss);
  // Named for a small budget whatever its rate: a run of a few evaluations that did not fall over its last
  // tenth (one or two line-search trials) says nothing of how many more it needs.
  if (more == 0)
    return format("cause: its budget ended it after %.0f evaluations (the objective did not fall over the last "
                  "tenth of them, too few evaluations to tell how many more it needs); change: raise "
                  "optimizer.max_evaluations",
                  facts.evaluations);
  return format("cause: its budget ended it after %.0f evaluations (the objective still fell %.2gx over the last "
                "tenth of them",
                facts.evaluations, 1 / std::max(facts.recent_improvement, 1e-300)) +
         format("; at that rate the worst keyframe needs about %.0f more to come within its tolerance); change: "
                "raise optimizer.max_evaluations",
                double(more));
}

// Noise at the start explains a run that stayed near it; one whose keyframe terms fell tenfold left it.
std::string likely_cause(const Sensitivity& s, const RunFacts& facts, double worst_miss, bool& budget_named) {
  if (every_trial_diverged(facts)) return diverged_cause(facts);
  if (unstable_edge(facts)) return unstable_cause(facts);
  if (s.noisy() && facts.keyframe_objective_end > 0.1 * facts.keyframe_objective_start)
    return format("cause: the objective is noise at the start (it moves by %.2g of itself under perturbations "
                  "of 1e-9): the start is a bifurcation, ",
                  s.relative_noise()) +
           (facts.flock ? "e.g. agents spawned on top of each other; change: a larger spawn disc or another seed"
                        : "e.g. a flat sheet released in its own plane buckles whichever way round-off says; change: "
                          "break the symmetry (a small initial velocity or offset out of plane) or put the keyframe "
                          "later");
  if (s.amplifying()) return amplifying_cause(s, facts);
  if (facts.budget && (facts.recent_improvement < 0.9 || facts.evaluations < kFewEvaluations)) {
    budget_named = true;
    return budget_cause(facts, worst_miss);
  }
  if (facts.descent.rough()) {
    const DescentProbe& d = facts.descent;
    return "cause: where the optimiser stopped the objective is rough or stiff: along its descent direction it " +
           (d.linear_fraction > 0 ? format("falls as the gradient predicts only over %.1g of the way the slope "
                                           "points to (a control change of %.2g)",
                                           d.linear_fraction, d.linear_fraction * d.reach())
                                  : std::string("does not fall as the gradient predicts even over 1e-06 of the way "
                                                "the slope points to")) +
           (facts.flock ? std::string(", so the line search stalls there: ") + kPackedAgents + "; change: " +
                              kSpreadAgents
                        : std::string(", so the line search stalls there: contact switching, a sheet balanced "
                                      "where a small push tips it, or a sheet pressed against a collider its target "
                                      "lies in or behind; change: move a keyframe that lies in or behind a collider, "
                                      "else friction on a collider that should hold the sheet, finer time steps "
                                      "(time.substeps), or a keyframe reached with less sliding contact"));
  }
  return smooth_cause(s, facts);
}

}  // namespace

Diagnosis diagnose(const std::vector<KeyframeJudgement>& keyframes, const Sensitivity& s, const RunFacts& facts) {
  Diagnosis d;
  const KeyframeJudgement* worst = worst_keyframe(keyframes);
  d.reached = !worst || worst->miss_after <= 1.0;
  d.far = worst && worst->miss_after > kFarMiss;
  d.progress = facts.keyframe_objective_end <= 0.5 * facts.keyframe_objective_start;
  const std::string budget = !facts.budget ? ""
                             : facts.scaled_budget > 0
                                 ? format(" (it stopped at the %.0f of its %.0f evaluations its plan gives a flight this large: ",
                                          facts.scaled_budget, facts.max_evaluations) +
                                       facts.status + ")"
                                 : " (it stopped at its budget: " + facts.status + ")";
  if (d.reached) {
    d.outcome = "reached";
    d.line = "reached its keyframes" + budget;
    return d;
  }
  d.outcome = !d.progress ? "no_progress" : d.far ? "not_reached" : "near";
  const std::string untouched = untouched_cause(keyframes);
  bool budget_named = false;
  const std::string cause = untouched.empty() ? likely_cause(s, facts, worst->miss_after, budget_named) : untouched;
  d.line = verdict_head(d, facts) + miss_text(*worst) + budget + "; " + cause;
  if (facts.budget && !budget_named && facts.evaluations > 0) d.line += budget_expectation(facts, worst->miss_after);
  if (!facts.fallback.empty()) d.line += "; " + facts.fallback;
  return d;
}

}  // namespace kf

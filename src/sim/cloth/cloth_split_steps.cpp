// The cloth's split policy: a step that gains energy is taken as two halves (checked_step), or as a held
// pattern says (held_step), and the patterns the runs took are recorded and handed out as the System's step
// schedule (sim/system.h), which the optimisation strategy holds so a line search meets no jump where the
// energy check would flip between trial points.
#include "sim/cloth/cloth_system.h"
#include "sim/cloth/cloth_split_pattern.h"

#include <cmath>

namespace kf {

kf::StepSchedule ClothSystem::step_schedule() const { return cloth_split_schedule(recorded_); }

void ClothSystem::hold_step_schedule(const kf::StepSchedule& schedule) {
  const StepSchedule* steps = cloth_split_steps(schedule);
  hold_schedule(steps ? *steps : StepSchedule{});
}

void ClothSystem::record_pattern(int n, bool ok, const ClothRecord& rec) {
  if (n >= int(recorded_.size())) recorded_.resize(n + 1);
  auto& pattern = recorded_[n];
  pattern.clear();  // keeps its capacity: a run after the first allocates nothing here
  if (ok)
    for (int k = 0; k < rec.count; ++k) pattern.push_back(std::uint8_t(rec.substeps[k].depth));
}

bool ClothSystem::held_step(int n, int depth, double t0, const VecX& x, const VecX& v, const VecX& u,
                            VecX& x_next, VecX& v_next, ClothRecord& rec, const std::vector<std::uint8_t>& pattern) {
  if (cursor_ >= pattern.size() || pattern[cursor_] < depth) return false;  // not a pattern a run recorded
  if (pattern[cursor_] == depth) {
    ++cursor_;
    if (!linear_step(n, depth, t0, x, v, u, x_next, v_next)) return false;
    accept_substep(depth, t0, x, v, rec);
    return true;
  }
  if (depth >= spec_.max_halvings) return false;
  VecX &xm = split_x_[depth], &vm = split_v_[depth];
  xm.resize(3 * p_);
  vm.resize(3 * p_);
  const double half = std::ldexp(1.0, -depth - 1);
  return held_step(n, depth + 1, t0, x, v, u, xm, vm, rec, pattern) &&
         held_step(n, depth + 1, t0 + half, xm, vm, u, x_next, v_next, rec, pattern);
}

bool ClothSystem::checked_step(int n, int depth, double t0, const VecX& x, const VecX& v, const VecX& u,
                               VecX& x_next, VecX& v_next, ClothRecord& rec) {
  const bool solved = linear_step(n, depth, t0, x, v, u, x_next, v_next);
  bool accept = solved;
  if (depth < spec_.max_halvings) {
    // Backward Euler with damping never gains energy; the linearised step does when it moves particles
    // fast across springs or into colliders, and halving the step shrinks what it invents ~4-16 times.
    // An explicit control's kick is external to the solve (it may store more spring energy than its
    // work in one step): the check measures the solve's own end state.
    const bool kick = spec_.explicit_controls();
    if (kick && solved) {
      solved_v_ = v + dv_ / spec_.theta;
      solved_x_ = x + std::ldexp(h_, -depth) * (v + dv_);
    }
    const VecX& xc = kick ? solved_x_ : x_next;
    const VecX& vc = kick ? solved_v_ : v_next;
    const Energy before = energy_at_start(n, x, v), after = solved ? energy(n, xc, vc) : Energy{};
    const double work = solved ? external_work(u, x, xc, !kick) : 0.0;
    // The energy the step moves is the tolerance's scale (a NaN gain fails the test and splits).
    const double moved = before.kinetic + before.elastic + before.contact + std::abs(work) +
                         std::abs(after.gravity - before.gravity);
    accept = solved && after.total() - before.total() - work <= 1e-3 * moved + 1e-12;
    if (accept && !kick) remember_energy(x_next, v_next, after);
  }
  if (accept) {
    accept_substep(depth, t0, x, v, rec);
    return true;
  }
  if (depth >= spec_.max_halvings) return false;
  VecX &xm = split_x_[depth], &vm = split_v_[depth];  // sized for every depth up front: no reallocation here
  xm.resize(3 * p_);
  vm.resize(3 * p_);
  const double half = std::ldexp(1.0, -depth - 1);
  return checked_step(n, depth + 1, t0, x, v, u, xm, vm, rec) &&
         checked_step(n, depth + 1, t0 + half, xm, vm, u, x_next, v_next, rec);
}

}  // namespace kf

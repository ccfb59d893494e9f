#include "adjoint/rollout.h"

#include <algorithm>

#include "adjoint/memory_estimate.h"

namespace kf {

Trajectory frames_of(const Rollout& r, const TimeSpec& t, int particles) {
  Trajectory traj;
  traj.particles = particles;
  traj.fps = t.fps;
  for (int n = 0; n <= r.steps(); n += t.substeps) {
    traj.x.push_back(r.x[n]);
    traj.v.push_back(r.v[n]);
  }
  return traj;
}

std::size_t Rollout::stored_bytes() const {
  std::size_t b = 0;
  for (const auto& s : x) b += sizeof(double) * s.size();
  for (const auto& s : v) b += sizeof(double) * s.size();
  for (const auto& s : context) b += sizeof(double) * s.size();
  return b;
}

namespace {

void ensure_size(VecX& a, int n) {
  if (a.size() != n) a.resize(n);
}

// Grows `tape` to n entries of the system's record type, keeping the ones there (they own work space).
void ensure_tape(const System& sys, std::vector<std::unique_ptr<StepRecord>>& tape, int n) {
  if (int(tape.size()) > n) tape.resize(n);
  while (int(tape.size()) < n) tape.push_back(sys.new_record());
}

// The kept states past step n (whose step diverged) hold the state of step n: no non-finite value (nor
// one left from an earlier rollout) reaches a trajectory written from a diverged rollout.
void hold_after_divergence(Rollout& r, int n, const VecX& x, const VecX& v) {
  for (int m = n + 1; m <= r.steps(); ++m)
    if (r.kept(m)) r.x[m] = x, r.v[m] = v;
}

}  // namespace

bool simulate(System& sys, const VecX& x0, const VecX& v0, int N, const StepControl& u, Rollout& r,
              const RolloutOptions& options) {
  const int dof = int(x0.size());
  int every = options.checkpoint_every;
  if (every <= 0 && options.memory_budget > 0) {
    int costed = 0;
    if (options.keep_for)
      for (int n = 0; n <= N; ++n) costed += options.keep_for->active(n);
    bool fits = false;
    every = checkpoint_spacing_for(estimate_rollout_memory(sys, N, costed), options.memory_budget, fits);
  }
  r.x.resize(N + 1);
  r.v.resize(N + 1);
  r.every = every;
  r.diverged_at = -1;
  auto keep = [&](int n) {
    return every <= 0 || n % every == 0 || n == N || (options.keep_for && options.keep_for->active(n));
  };
  // Entries not kept are released, so a Rollout reused in checkpointed mode shrinks.
  for (int n = 0; n <= N; ++n) {
    if (keep(n)) {
      ensure_size(r.x[n], dof);
      ensure_size(r.v[n], dof);
    } else {
      r.x[n].resize(0);
      r.v[n].resize(0);
    }
  }
  r.context.resize(every > 0 ? (N + every - 1) / every + 1 : 0);
  // Checkpointed: steps record into one scratch entry; the backward pass records its segments again.
  // Without a tape the entries already there are kept (the next evaluation with a gradient reuses them)
  // but none is added.
  const bool one_entry = every > 0 || !options.tape;
  if (every > 0) ensure_tape(sys, r.tape, 1);
  else if (!options.tape) ensure_tape(sys, r.tape, std::clamp(int(r.tape.size()), 1, std::max(N, 1)));
  else ensure_tape(sys, r.tape, N);
  r.x[0] = x0;
  r.v[0] = v0;
  // States not kept alternate between two scratch pairs so a step never reads what it writes.
  VecX scratch_x[2], scratch_v[2];
  if (every > 0)
    for (int k = 0; k < 2; ++k) {
      scratch_x[k].resize(dof);
      scratch_v[k].resize(dof);
    }
  const VecX *xc = &r.x[0], *vc = &r.v[0];
  for (int n = 0; n < N; ++n) {
    if (every > 0 && n % every == 0) sys.save_step_context(n, r.context[n / every]);
    VecX& xn = r.kept(n + 1) ? r.x[n + 1] : scratch_x[n & 1];
    VecX& vn = r.kept(n + 1) ? r.v[n + 1] : scratch_v[n & 1];
    StepRecord& record = *r.tape[one_entry ? 0 : n];
    if (!sys.step(n, *xc, *vc, u(n), xn, vn, record)) {
      r.diverged_at = n;
      hold_after_divergence(r, n, *xc, *vc);
      return false;
    }
    xc = &xn;
    vc = &vn;
  }
  return true;
}

bool simulate(System& sys, const VecX& x0, const VecX& v0, const std::vector<VecX>& U, Rollout& r) {
  return simulate(sys, x0, v0, int(U.size()), [&](int n) -> const VecX& { return U[n]; }, r);
}

bool simulate_frames(System& sys, const VecX& x0, const VecX& v0, const TimeSpec& t, Rollout& r) {
  const VecX zero = VecX::Zero(x0.size());
  return simulate(sys, x0, v0, t.steps(), [&](int) -> const VecX& { return zero; }, r,
                  {.checkpoint_every = t.substeps});
}

double cost_value(const StateCost& cost, const Rollout& r) {
  double phi = 0;
  const int dof = int(r.x[0].size());
  VecX gx = VecX::Zero(dof), gv = VecX::Zero(dof);
  for (int n = 0; n <= r.steps(); ++n)
    if (cost.active(n)) phi += cost.eval(n, r.x[n], r.v[n], gx, gv);
  return phi;
}

void backward(System& sys, const Rollout& r, const StepControl& u, const StateCost& cost,
              const StepControlGradient& du, VecX& dx0, VecX& dv0, int first) {
  const int N = r.steps(), dof = int(r.x[0].size());
  first = std::clamp(first, 0, N);
  // A spacing past the end means one segment of N steps: buffers of N + 1 states, not of `every` (a spacing
  // of 10^7 on a 10-step run would otherwise ask for 10^7 states).
  const int every = r.every > 0 ? std::min(r.every, std::max(N, 1)) : N + 1;
  VecX xhat = VecX::Zero(dof), vhat = VecX::Zero(dof), xhat_prev(dof), vhat_prev(dof), uhat(dof);
  if (cost.active(N)) cost.eval(N, r.x[N], r.v[N], xhat, vhat);
  // Segment buffers: states k .. e of the segment being walked back and its tape (checkpointed mode only).
  std::vector<VecX> seg_x(r.every > 0 ? every + 1 : 0), seg_v(seg_x.size());
  for (auto& s : seg_x) s.resize(dof);
  for (auto& s : seg_v) s.resize(dof);
  std::vector<std::unique_ptr<StepRecord>> seg_tape;
  if (r.every > 0) ensure_tape(sys, seg_tape, every);
  const int last_start = r.every > 0 ? ((N - 1) / every) * every : 0;
  for (int k = last_start; k >= 0 && std::min(k + every, N) > first; k -= every) {
    const int e = std::min(k + every, N);
    auto state_x = [&](int n) -> const VecX& { return r.every > 0 ? seg_x[n - k] : r.x[n]; };
    auto state_v = [&](int n) -> const VecX& { return r.every > 0 ? seg_v[n - k] : r.v[n]; };
    auto record = [&](int n) -> const StepRecord& { return r.every > 0 ? *seg_tape[n - k] : *r.tape[n]; };
    if (r.every > 0) {
      // Recompute steps k .. e-1 from the checkpoint, in the original step context, for their states and
      // tape (state e is recomputed too, and equals the kept one bit for bit).
      seg_x[0] = r.x[k];
      seg_v[0] = r.v[k];
      sys.restore_step_context(k, r.context[k / every]);
      for (int n = k; n < e; ++n)
        sys.step(n, seg_x[n - k], seg_v[n - k], u(n), seg_x[n - k + 1], seg_v[n - k + 1], *seg_tape[n - k]);
    }
    for (int n = e - 1; n >= std::max(k, first); --n) {
      if (xhat.isZero(0.0) && vhat.isZero(0.0)) {
        // After the last keyframe (a sheet landing, say) the adjoint is exactly zero and the step's
        // adjoint linear in it: skip its solve.
        uhat.setZero();
        du(n, uhat);
      } else {
        sys.step_adjoint(n, state_x(n), state_v(n), u(n), record(n), xhat, vhat, xhat_prev, vhat_prev, uhat);
        du(n, uhat);
        xhat.swap(xhat_prev);
        vhat.swap(vhat_prev);
      }
      if (cost.active(n)) cost.eval(n, state_x(n), state_v(n), xhat, vhat);
    }
  }
  dx0 = xhat;
  dv0 = vhat;
}

void backward(System& sys, const Rollout& r, const std::vector<VecX>& U, const StateCost& cost,
              std::vector<VecX>& dU, VecX& dx0, VecX& dv0) {
  dU.resize(r.steps());
  backward(
      sys, r, [&](int n) -> const VecX& { return U[n]; }, cost, [&](int n, const VecX& g) { dU[n] = g; }, dx0,
      dv0);
}

}  // namespace kf

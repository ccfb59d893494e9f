#pragma once
// A particle system with one integrator: the forward step and its adjoint side by side.
//
// State: positions x and velocities v, 3p entries each (metres, m/s, world frame, Y up).
// Controls: an external force u_n (3p, newtons) applied during step n (n = 0 .. steps-1).
// The step length h is fixed when the system is built from a scene.
#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/types.h"

namespace kf {

// The discrete decisions a system's steps took (the cloth: which steps its energy check split, and how),
// kept by the optimisation strategy and handed back so later runs repeat them: a rollout is then a smooth
// function of the controls. Opaque outside the system that made it; empty when there are none.
class StepSchedule {
 public:
  struct Pattern {
    virtual ~Pattern() = default;
    virtual int steps() const = 0;  // the steps it covers
  };
  StepSchedule() = default;
  explicit StepSchedule(std::shared_ptr<const Pattern> p) : p_(std::move(p)) {}
  bool empty() const { return !p_; }
  int steps() const { return p_ ? p_->steps() : 0; }
  const Pattern* pattern() const { return p_.get(); }

 private:
  std::shared_ptr<const Pattern> p_;
};

// What one forward step leaves for its adjoint: one entry of a rollout's tape. Each system derives its own
// (the cloth keeps the step's velocity change, the flock its neighbour lists); the base records nothing.
struct StepRecord {
  virtual ~StepRecord() = default;
};

class System {
 public:
  virtual ~System() = default;

  virtual int particles() const = 0;
  int dof() const { return 3 * particles(); }
  virtual double h() const = 0;
  // Per-particle masses (p entries, kg).
  virtual const VecX& masses() const = 0;
  // Initial state at step 0 (the scene's; controls on initial velocity replace v afterwards).
  virtual void initial_state(VecX& x, VecX& v) const = 0;
  // True for flocks that live on the ground plane: the y components of x, v and u stay zero.
  virtual bool planar() const { return false; }

  // A fresh tape entry for this system's steps.
  virtual std::unique_ptr<StepRecord> new_record() const { return std::make_unique<StepRecord>(); }
  // Bytes one tape entry is expected to hold, for the memory estimate made before a run (it decides
  // whether to checkpoint). Systems without their own estimate count one state's worth (6p doubles).
  virtual std::size_t record_bytes_estimate() const { return 6 * sizeof(double) * std::size_t(particles()); }

  // Advances the state of step n by one step under control force u and writes what its adjoint needs to
  // `record`. Returns false when the result is not finite, an inner solve failed or the step is unstable
  // at this state (divergence_reason says why); the caller treats that as a diverged simulation. x_next
  // and v_next arrive sized 3p. Must not allocate after the first call with the same record.
  virtual bool step(int n, const VecX& x, const VecX& v, const VecX& u, VecX& x_next, VecX& v_next,
                    StepRecord& record) = 0;

  // Adjoint of step n, evaluated at the forward state (x, v) of step n, its control u and the record its
  // forward step wrote.
  // In:  xhat1, vhat1 = dphi/dx_{n+1}, dphi/dv_{n+1} (complete, including keyframe terms at n+1).
  // Out: xhat, vhat   = the part of dphi/dx_n, dphi/dv_n that flows through this step
  //                     (the caller adds the keyframe gradient of step n),
  //      uhat         = dphi/du_n through the dynamics (the caller adds the effort term alpha*u_n).
  virtual void step_adjoint(int n, const VecX& x, const VecX& v, const VecX& u, const StepRecord& record,
                            const VecX& xhat1, const VecX& vhat1, VecX& xhat, VecX& vhat, VecX& uhat) = 0;

  // The same without a tape, for single steps outside a rollout: the step records into a scratch entry,
  // and the adjoint first repeats the forward step to record it.
  bool step(int n, const VecX& x, const VecX& v, const VecX& u, VecX& x_next, VecX& v_next) {
    return step(n, x, v, u, x_next, v_next, scratch_record());
  }
  void step_adjoint(int n, const VecX& x, const VecX& v, const VecX& u, const VecX& xhat1, const VecX& vhat1,
                    VecX& xhat, VecX& vhat, VecX& uhat) {
    VecX x1(x.size()), v1(v.size());
    StepRecord& r = scratch_record();
    step(n, x, v, u, x1, v1, r);
    step_adjoint(n, x, v, u, r, xhat1, vhat1, xhat, vhat, uhat);
  }

  // Solver state besides (x, v) that step n depends on (e.g. a PCG warm start carried over from step
  // n-1), so that a step recomputed from a checkpoint repeats the original bit for bit. Saved just
  // before step n runs; empty when there is none. Restoring it makes the next step(n, ...) behave as it
  // did in the original sequence.
  virtual void save_step_context(int /*n*/, VecX& context) const { context.resize(0); }
  virtual void restore_step_context(int /*n*/, const VecX& /*context*/) {}

  // One-line description for logs ("flock: 200 agents, grid neighbour search").
  virtual std::string describe() const = 0;
  // Why the last step that returned false failed, with what would help, in the scene's words; empty when
  // it only met values that are not finite.
  virtual std::string divergence_reason() const { return {}; }

  // The step decisions of the runs so far (step_schedule), held so that every later run repeats them
  // (hold_step_schedule; steps past its end decide afresh) until released. Systems that decide nothing
  // return an empty schedule and ignore the rest.
  virtual StepSchedule step_schedule() const { return {}; }
  virtual void hold_step_schedule(const StepSchedule& /*schedule*/) {}
  virtual void release_step_schedule() {}

  // Named counters of the last forward simulation for run reports (a cape's collision contacts).
  virtual std::vector<std::pair<std::string, double>> run_stats() const { return {}; }

 private:
  StepRecord& scratch_record() {
    if (!scratch_) scratch_ = new_record();
    return *scratch_;
  }
  std::unique_ptr<StepRecord> scratch_;
};

}  // namespace kf

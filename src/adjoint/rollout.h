#pragma once
// Forward simulation and the adjoint pass that walks it backwards, with optional checkpointing.
//
// Every step writes a tape entry (System::StepRecord) that its adjoint step reads.
// Stored mode (checkpoint_every = 0) keeps all N+1 states and all N tape entries. Checkpointed mode keeps
// every k-th state (plus the system's step context there, e.g. a PCG warm start), the last state and the
// states a cost reads, and no tape; the backward pass recomputes each segment of k steps from its
// checkpoint into a k-state buffer and a k-entry tape.
// Memory for states falls from (N+1) to about N/k + k + (cost steps) states, at the price of about one
// more forward pass. Recomputed states are bit-identical to the originals (same steps, same inputs,
// same step context), so both modes give the same gradient bit for bit.
#include <cstddef>
#include <algorithm>
#include <functional>
#include <memory>
#include <vector>

#include "core/trajectory.h"
#include "core/types.h"
#include "scene/time_spec.h"
#include "sim/system.h"

namespace kf {

// States of one simulation of N steps: x[n], v[n] (3p each) where kept, empty (size 0) where not.
struct Rollout {
  std::vector<VecX> x, v;
  std::vector<std::unique_ptr<StepRecord>> tape;  // entry n written by step n (stored mode; else empty)
  std::vector<VecX> context;  // step context saved before step c*every, per checkpoint c (checkpointed)
  int every = 0;              // checkpoint spacing in steps; 0 = every state kept
  int diverged_at = -1;       // first step whose result was not finite, or -1
  int steps() const { return int(x.size()) - 1; }
  bool kept(int n) const { return x[n].size() > 0; }
  // Bytes held by the state vectors and step contexts (what checkpointing saves; the tape is not counted).
  std::size_t stored_bytes() const;
};

// The frames of a rollout kept in every state (every t.substeps-th state, from 0): the trajectory of a run.
Trajectory frames_of(const Rollout& r, const TimeSpec& t, int particles);

// A sum of terms g_n(x_n, v_n) over steps; zero at most steps.
class StateCost {
 public:
  virtual ~StateCost() = default;
  virtual bool active(int n) const = 0;
  // Returns g_n and adds dg_n/dx_n to gx and dg_n/dv_n to gv (both 3p).
  virtual double eval(int n, const VecX& x, const VecX& v, VecX& gx, VecX& gv) const = 0;
};

// The control force of step n (3p, N). Asked for one step at a time, so controls held over a frame
// (or absent) need no per-step storage; the returned reference stays valid until the next call.
using StepControl = std::function<const VecX&(int n)>;
// Receives dphi/du_n (3p) through the dynamics for each step n, in the order N-1 .. 0.
using StepControlGradient = std::function<void(int n, const VecX& uhat)>;

struct RolloutOptions {
  int checkpoint_every = 0;             // 0: keep every state (unless the budget below asks otherwise)
  const StateCost* keep_for = nullptr;  // checkpointed: also keep the states where this cost is active
  // Bytes the rollout's states and tape may hold (0: no limit). With checkpoint_every = 0, a rollout
  // whose estimate (adjoint/memory_estimate.h) passes it is checkpointed at the spacing that needs least.
  std::size_t memory_budget = 0;
  // false: no tape is kept (an evaluation without a gradient; backward cannot follow): every step records
  // into the first entry, so such a run holds one entry however many steps it has.
  bool tape = true;
};

// Runs N steps from (x0, v0) under the controls. Returns false (and sets diverged_at) when a step
// fails; states after it are left as they were.
bool simulate(System& sys, const VecX& x0, const VecX& v0, int N, const StepControl& u, Rollout& r,
              const RolloutOptions& options = {});
// The same with all N = U.size() per-step forces given, every state kept.
bool simulate(System& sys, const VecX& x0, const VecX& v0, const std::vector<VecX>& U, Rollout& r);

// The uncontrolled simulation of t.steps() steps keeping only the frames' states (every t.substeps-th) and no
// tape: what `keyframe simulate` saves, without the memory of every step's state.
bool simulate_frames(System& sys, const VecX& x0, const VecX& v0, const TimeSpec& t, Rollout& r);

// Sum of the cost over the rollout's states (every active step must be kept).
double cost_value(const StateCost& cost, const Rollout& r);

// Adjoint pass over a successful rollout: dphi/du_n to `du` for n = N-1 .. first, and dx0, dv0 =
// dphi/dx_first, dphi/dv_first (first = 0: the initial state's). Checkpointed rollouts are recomputed
// segment by segment (this runs sys.step). A `first` above 0 skips the steps before it: their forces are
// not controls and the start state is given.
void backward(System& sys, const Rollout& r, const StepControl& u, const StateCost& cost,
              const StepControlGradient& du, VecX& dx0, VecX& dv0, int first = 0);
// The same with per-step forces U and gradients dU (resized to N).
void backward(System& sys, const Rollout& r, const std::vector<VecX>& U, const StateCost& cost,
              std::vector<VecX>& dU, VecX& dx0, VecX& dv0);

}  // namespace kf

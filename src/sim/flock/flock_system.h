#pragma once
// A flock on the ground plane: explicit step of paper eq. 1 and its exact adjoint.
//
//   v1 = v + h M^-1 (f(x, v) + u),  x1 = x + h v1          (forward)
//   s = vhat1 + h xhat1,  xhat = xhat1 + h K^T M^-1 s,  vhat = s + h D^T M^-1 s,  uhat = h M^-1 s
// with K = df/dx, D = df/dv at (x_n, v_n) applied matrix-free.
// With implicit damping (FlockSpec::implicit_damping) an agent's own-velocity damping, a_i v_i with
// a_i = h (c S_i + drag) / m_i and S_i = sum_j w_ij its summed matching weights, is taken at v1 instead of v:
//   v1_i = v_i + h/(m_i (1 + a_i)) (f_i + u_i)
// which multiplies v_i by 1/(1 + a_i) where the explicit step multiplies it by 1 - a_i: stable however
// densely agents pack. Its adjoint is the explicit one with M^-1 s replaced by y_i = s_i / (m_i (1 + a_i)),
// plus, since a_i depends on x through S_i, xhat_j += h sum_i q_i dS_i/dx_j with
// q_i = -(y_i . (f_i + u_i)) h c / (m_i (1 + a_i)); f_i + u_i and 1 + a_i come from the step's record. The three
// neighbour forces run fused in one pass over each agent's whole list (NeighborForces), each agent summing its own pair
// terms in its list's order, so results do not depend on the thread count; wander and drag are per-agent terms. A
// pair's terms are computed by both of its agents: at a bunched crowd's hundreds of neighbours, storing them once and
// reading them back twice moved more memory than computing them again costs.
// The forward step records the centering quantities it found (FlockRecord, the step's tape entry); its
// adjoint repeats the neighbour search at the step's state (the same lists, bit for bit) rather than
// reading them from the tape: the lists are most of a bunched crowd's tape (4 bytes per neighbour entry
// and step, 1 GB at 10,000 agents) and the search a small part of a step's work. Each pass finds an
// agent's list just before it uses it (NeighborGrid::neighbors_of_slot) and keeps none, over agent data
// packed in the grid's slot order.
// Planar: the y components of x1, v1 and of every adjoint output are exactly zero (y of u is ignored).
#include <memory>
#include <span>
#include <vector>

#include "scene/flock_spec.h"
#include "sim/flock/flock_force.h"
#include "sim/flock/neighbor_forces.h"
#include "sim/flock/neighbor_grid.h"
#include "sim/system.h"

namespace kf {

// What a flock step found at its state that its adjoint cannot cheaply find again: the centering quantities
// (offset m_i - x_i in the ground plane, m, and b_i; p each, in the slot order of the step's state, which
// its adjoint finds again). With implicit damping also each agent's total force f_i + u_i and 1 + a_i (per
// agent).
struct FlockRecord final : StepRecord {
  std::vector<Planar> offset;
  std::vector<double> b;
  std::vector<Planar> force;
  std::vector<double> divisor;
  std::size_t bytes() const {
    return (offset.capacity() + force.capacity()) * sizeof(Planar) +
           (b.capacity() + divisor.capacity()) * sizeof(double);
  }
};

class FlockSystem final : public System {
 public:
  // h: step (s); steps: how many steps the wander table covers (later steps are computed on demand);
  // h_ref: the scene's own step, so wander varies at the same rate in time when h is overridden.
  FlockSystem(const FlockSpec& spec, double h, int steps, unsigned seed, double h_ref = 0);

  int particles() const override { return spec_.agents; }
  double h() const override { return h_; }
  const VecX& masses() const override { return masses_; }
  void initial_state(VecX& x, VecX& v) const override;
  bool planar() const override { return true; }
  std::unique_ptr<StepRecord> new_record() const override { return std::make_unique<FlockRecord>(); }
  // Centering quantities: 24 bytes per agent, however the agents bunch (48 with implicit damping).
  std::size_t record_bytes_estimate() const override;
  using System::step;
  using System::step_adjoint;
  bool step(int n, const VecX& x, const VecX& v, const VecX& u, VecX& x_next, VecX& v_next,
            StepRecord& record) override;
  void step_adjoint(int n, const VecX& x, const VecX& v, const VecX& u, const StepRecord& record, const VecX& xhat1,
                    const VecX& vhat1, VecX& xhat, VecX& vhat, VecX& uhat) override;
  std::string describe() const override;
  std::string divergence_reason() const override;

  // The pieces of a step, exposed for derivative checks. All vectors 3p.
  // Total force f(x, v) at step n (N), without controls.
  void forces(int n, const VecX& x, const VecX& v, VecX& f);
  // K^T y and D^T y at (x, v), step n.
  void apply_KT_DT(int n, const VecX& x, const VecX& v, const VecX& y, VecX& KTy, VecX& DTy);

 private:
  // Sorts the agents at x into the grid's slots and packs motion_ in slot order (nothing without
  // neighbour forces: then slot k is agent k).
  void index(const VecX& x, const VecX& v);
  int slot(int i) const { return neighbor_forces_.any() ? grid_.slot_of(i) : i; }
  // The slots of slot k's neighbours, in this thread's work space (valid until its next call).
  std::span<int> slot_neighbors(int k) const;
  void size_record(FlockRecord& r) const;
  // Forward neighbour pass over the slots (motion_ packed): each slot's neighbour force and matching's
  // damping of its own velocity (neighbor_terms_), and r's offset and b. The per-agent work then runs in
  // agent order, reading one slot's terms, where reading each agent's vectors in slot order would miss the
  // cache at every one of them.
  void neighbor_pass(FlockRecord& r);
  // The explicit step's velocity update multiplies agent i's own velocity by 1 - h (c sum_j w_ij + drag)/m_i
  // (the diagonal of I + h M^-1 D). At 2 or more that factor is -1 or less, and since the diagonal entry of
  // a symmetric matrix lies within its eigenvalues, I + h M^-1 D then has an eigenvalue of -1 or less: the
  // step amplifies relative velocities in packed agents step after step (a 100,000-agent crowd reached
  // 3,800 m/s). Such a step is refused like a diverged one. overshoot_[i] holds h (c sum w + drag)/m_i.
  bool stable_velocity_update(int n);
  // Packs adjoint_ in slot order for the transposed pass at the state of r (motion_ packed), applied to y,
  // with q (per agent) when given.
  void pack_adjoint(const FlockRecord& r, const VecX& y, const std::vector<double>* q = nullptr);
  // The adjoint's y = M^-1 s (divided by 1 + a_i with implicit damping) and, with implicit damping, q_ / h.
  void adjoint_weights(const FlockRecord& r, const VecX& xhat1, const VecX& vhat1);
  void check_size(const VecX& x, const VecX& v) const;
  // Transposed neighbour pass over the slots (adjoint_ packed) into neighbor_transposed_; with
  // `summed_weights`, K^T y also gets the q term (adjoint_ packed with q).
  void transposed_pass(bool summed_weights);
  // (K^T y)_j and (D^T y)_j of all forces for agent j (after transposed_pass).
  void transpose_apply(int n, const VecX& x, const VecX& v, const VecX& y, int j, Vec3& kt, Vec3& dt) const;
  Vec3 local_force(int n, const VecX& v, int i) const;  // wander + drag on agent i

  FlockSpec spec_;
  double h_;
  unsigned seed_;
  VecX masses_;
  NeighborForces neighbor_forces_;
  std::vector<std::unique_ptr<FlockForce>> local_forces_;  // per-agent terms: wander, drag
  NeighborGrid grid_;                                      // the state being stepped or adjoined, sorted into slots
  std::vector<AgentMotion> motion_;                        // that state, packed in slot order (p)
  std::vector<AgentAdjoint> adjoint_;                      // the same with y and the centering quantities (p)
  // Per slot: the neighbour force (N) and matching's own-velocity damping (N/(m/s)) of the forward pass, and
  // the neighbour terms' (K^T y, D^T y) of the transposed one.
  struct NeighborTerms {
    Planar force;
    double damping = 0;
  };
  struct NeighborTransposed {
    Planar kt, dt;
  };
  std::vector<NeighborTerms> neighbor_terms_;
  std::vector<NeighborTransposed> neighbor_transposed_;
  FlockRecord scratch_;            // forces() and apply_KT_DT
  VecX y_;                         // M^-1 s in the adjoint step
  std::vector<double> q_;          // q_i / h in the adjoint step with implicit damping (p)
  std::vector<double> overshoot_;  // per agent, the last step's h (c sum w + drag)/m (p)
  int unstable_step_ = -1;         // the last step refused as unstable (-1: none), and its largest overshoot
  double unstable_overshoot_ = 0;
};

}  // namespace kf

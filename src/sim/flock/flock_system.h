#pragma once
// A flock on the ground plane: explicit step of paper eq. 1 and its exact adjoint.
//
//   v1 = v + h M^-1 (f(x, v) + u),  x1 = x + h v1          (forward)
//   s = vhat1 + h xhat1,  xhat = xhat1 + h K^T M^-1 s,  vhat = s + h D^T M^-1 s,  uhat = h M^-1 s
// with K = df/dx, D = df/dv at (x_n, v_n) applied matrix-free. The three neighbour forces run fused in one
// pass over each agent's list (NeighborForces), each pair's terms computed once (PairIndex) and gathered by
// both agents in a fixed order, so results do not depend on the thread count; wander and drag are per-agent
// terms.
// The forward step records the neighbour lists and centering means it found (FlockRecord, the step's tape
// entry); its adjoint reads them, so one adjoint step costs one transposed pass and no neighbour search.
// Planar: the y components of x1, v1 and of every adjoint output are exactly zero (y of u is ignored).
#include <memory>
#include <vector>

#include "scene/flock_spec.h"
#include "sim/flock/flock_force.h"
#include "sim/flock/neighbor_forces.h"
#include "sim/flock/neighbor_grid.h"
#include "sim/flock/pair_buffer.h"
#include "sim/flock/pair_index.h"
#include "sim/system.h"

namespace kf {

// What a flock step found at its state: neighbour lists, each pair once under its owner
// (NeighborGrid::search_owned), and centering quantities (offset m_i - x_i in the ground plane, m, and b_i;
// p each).
struct FlockRecord final : StepRecord {
  NeighborLists lists;
  std::vector<Planar> offset;
  std::vector<double> b;
  std::size_t bytes() const { return lists.bytes() + offset.capacity() * sizeof(Planar) + b.capacity() * sizeof(double); }
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
  // Lists (4 bytes per neighbour entry, 8 per agent) and centering quantities (24 bytes per agent). The
  // entries are twice those at the spawn (agents bunch as they are steered), or a quarter more than the
  // most any step has found so far, whichever is larger.
  std::size_t record_bytes_estimate() const override;
  using System::step;
  using System::step_adjoint;
  bool step(int n, const VecX& x, const VecX& v, const VecX& u, VecX& x_next, VecX& v_next,
            StepRecord& record) override;
  void step_adjoint(int n, const VecX& x, const VecX& v, const VecX& u, const StepRecord& record, const VecX& xhat1,
                    const VecX& vhat1, VecX& xhat, VecX& vhat, VecX& uhat) override;
  std::string describe() const override;

  // The pieces of a step, exposed for derivative checks. All vectors 3p.
  // Total force f(x, v) at step n (N), without controls.
  void forces(int n, const VecX& x, const VecX& v, VecX& f);
  // K^T y and D^T y at (x, v), step n.
  void apply_KT_DT(int n, const VecX& x, const VecX& v, const VecX& y, VecX& KTy, VecX& DTy);

 private:
  // Fills `r` for x: neighbour search, and the centering quantities when `with_centering` (then motion_
  // holds x and v packed).
  void search(FlockRecord& r, const VecX& x, const VecX& v, bool with_centering);
  // Each owned pair's forward terms at the state of r (motion_ packed) into forward_pairs_.
  void compute_forward_pairs(const FlockRecord& r);
  // Forward neighbour pass for agent i from forward_pairs_: adds the force to f, records offset_i and b_i.
  void add_neighbor_force(FlockRecord& r, int i, Vec3& f) const;
  // Packs adjoint_ for the transposed pass at the state of r (motion_ packed), applied to y, and computes
  // each owned pair's transposed terms into transposed_pairs_.
  void pack_adjoint(const FlockRecord& r, const VecX& y);
  void check_size(const VecX& x, const VecX& v) const;
  // (K^T y)_j and (D^T y)_j of all forces at the state of record r (adjoint_ packed for it).
  void transpose_apply(const FlockRecord& r, int n, const VecX& x, const VecX& v, const VecX& y, int j, Vec3& kt,
                       Vec3& dt) const;
  Vec3 local_force(int n, const VecX& v, int i) const;  // wander + drag on agent i

  FlockSpec spec_;
  double h_;
  unsigned seed_;
  VecX masses_;
  NeighborForces neighbor_forces_;
  std::vector<std::unique_ptr<FlockForce>> local_forces_;  // per-agent terms: wander, drag
  NeighborGrid grid_;    // search work space, shared by all steps
  std::vector<AgentMotion> motion_;    // the state being stepped, packed (p)
  std::vector<AgentAdjoint> adjoint_;  // the same with y and the centering quantities (p)
  PairIndex pair_index_;                // of the lists being evaluated
  // Per pair (pair_index_), in one buffer: the forward terms of the state last packed, or its transposed ones
  // (whichever was computed last; the other pointer is null).
  PairBuffer pair_buffer_;
  PairForward* forward_pairs_ = nullptr;
  PairTransposed* transposed_pairs_ = nullptr;
  int spawn_entries_ = 0;  // neighbour entries at the initial state
  int most_entries_ = 0;   // the most any step has found
  FlockRecord scratch_;  // forces() and apply_KT_DT
  VecX y_;  // M^-1 s in the adjoint step
};

}  // namespace kf

#pragma once
// A flock on the ground plane: explicit step of paper eq. 1 and its exact adjoint.
//
//   v1 = v + h M^-1 (f(x, v) + u),  x1 = x + h v1          (forward)
//   s = vhat1 + h xhat1,  xhat = xhat1 + h K^T M^-1 s,  vhat = s + h D^T M^-1 s,  uhat = h M^-1 s
// with K = df/dx, D = df/dv recomputed at (x_n, v_n) in the backward pass and applied matrix-free.
// Planar: the y components of x1, v1 and of every adjoint output are exactly zero (y of u is ignored).
#include <memory>
#include <vector>

#include "scene/flock_spec.h"
#include "sim/flock/flock_force.h"
#include "sim/flock/neighbor_grid.h"
#include "sim/system.h"

namespace kf {

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
  bool step(int n, const VecX& x, const VecX& v, const VecX& u, VecX& x_next, VecX& v_next) override;
  void step_adjoint(int n, const VecX& x, const VecX& v, const VecX& u, const VecX& xhat1, const VecX& vhat1,
                    VecX& xhat, VecX& vhat, VecX& uhat) override;
  std::string describe() const override;

  // The pieces of a step, exposed for derivative checks. All vectors 3p.
  // Total force f(x, v) at step n (N), without controls.
  void forces(int n, const VecX& x, const VecX& v, VecX& f);
  // K^T y and D^T y at (x, v), step n.
  void apply_KT_DT(int n, const VecX& x, const VecX& v, const VecX& y, VecX& KTy, VecX& DTy);

 private:
  // Neighbours and per-agent force data at (x, v).
  FlockState prepare(int n, const VecX& x, const VecX& v);

  FlockSpec spec_;
  double h_;
  unsigned seed_;
  VecX masses_;
  std::vector<std::unique_ptr<FlockForce>> forces_;
  double neighbor_radius_ = 0;
  NeighborGrid grid_;
  VecX y_;  // M^-1 s in the adjoint step
};

}  // namespace kf

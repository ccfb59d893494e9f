#pragma once
// Choi-Ko cloth stepped by linearised backward Euler (design §4), with its approximate adjoint.
//
// Forward:  A dv = b, A = M - h D - h^2 K, b = h (f + h K v + u), solved by PCG (IC(0)) with pinned
//           particles filtered out (Baraff-Witkin); v1 = v + dv, x1 = x + h v1.
// Backward: A^T w = vhat1 + h xhat1 on the free set, vhat = M w, xhat = xhat1 + h K^T w, uhat = h w.
// In A (both passes) K is the springs' definite stiffness (compressive transverse part dropped) plus the
// colliders' normal stiffness, D the spring damping and air drag; the non-symmetric position derivative
// of spring damping is left out of A in both passes, so A is symmetric and the backward solve reuses the
// forward PCG. The K^T w of xhat is not a solve: it uses the exact df/dx (springs, damping, collider
// curvature), since any bias there is O(h) per step and would not shrink as h falls.
// A is recomputed at (x_n, v_n) in the backward pass rather than stored.
// PCG starts from the previous step's solution when steps come in sequence (n after n-1 forward, n after
// n+1 backward) and from zero otherwise, so a rollout is the same function of its inputs on every run.
// A pinned particle is moved to its PinTrack position at n+1 whatever its state, so no adjoint flows
// through its own x, v (vhat = 0 there); only its coupling to free neighbours reaches xhat.
#include <memory>
#include <vector>

#include "scene/cloth_spec.h"
#include "sim/cloth/block_sparse.h"
#include "sim/cloth/buckling_spring.h"
#include "sim/cloth/collider.h"
#include "sim/cloth/filtered_pcg.h"
#include "sim/cloth/pin_track.h"
#include "sim/system.h"

namespace kf {

class ClothSystem final : public System {
 public:
  // h: step length, s. `pins` defaults to StaticPins. `extra_colliders` act after the spec's colliders
  // (a character's body, self-collision); callers that update them per step keep raw pointers.
  ClothSystem(const ClothSpec& spec, double h, std::unique_ptr<PinTrack> pins = nullptr,
              std::vector<std::unique_ptr<Collider>> extra_colliders = {});

  int particles() const override { return p_; }
  double h() const override { return h_; }
  const VecX& masses() const override { return mass_; }
  void initial_state(VecX& x, VecX& v) const override;
  bool step(int n, const VecX& x, const VecX& v, const VecX& u, VecX& x_next, VecX& v_next) override;
  void step_adjoint(int n, const VecX& x, const VecX& v, const VecX& u, const VecX& xhat1, const VecX& vhat1,
                    VecX& xhat, VecX& vhat, VecX& uhat) override;
  std::string describe() const override;
  // The PCG warm start of step n (the solution of step n-1 when that was the last forward solve).
  void save_step_context(int n, VecX& context) const override;
  void restore_step_context(int n, const VecX& context) override;

  // Opt-in (off by default): the adjoint also carries the spring terms the integrator swap drops,
  // d/dx of w^T [h^2 K(x) v_{n+1} + h D(x) dv] (K, D the springs' blocks of A), the position derivative of
  // the implicit matrix met by the step's velocity change. Central differences of each spring's 3x3
  // blocks give it; the forward pass keeps every step's dv for it. Where the pins drive the cloth hard
  // (a cape on a moving body) the dropped terms dominate the adjoint's error.
  void set_exact_spring_adjoint(bool on) { exact_springs_ = on; }

  // Evaluates forces f and the blocks of K, D and A at (x, v) of step n (the forward pass does this).
  void assemble(int n, const VecX& x, const VecX& v);
  // Results of the last assemble: f (3p, N), K (N/m), D (N s/m), A (kg), as Eigen matrices (allocate).
  const VecX& force() const { return force_; }
  SpMat stiffness_matrix() const { return K_.to_sparse(); }
  SpMat damping_matrix() const { return D_.to_sparse(); }
  SpMat system_matrix() const { return A_.to_sparse(); }

  const ClothSpec& spec() const { return spec_; }
  const std::vector<BucklingSpring>& springs() const { return springs_; }
  int damped_springs() const { return damped_; }
  int colliders() const { return int(colliders_.size()); }
  bool pinned(int i) const { return !free_[i]; }
  // PCG iterations of the last forward / backward solve (benchmarks, logs).
  int last_cg_iterations() const { return last_cg_; }
  int last_adjoint_cg_iterations() const { return last_adjoint_cg_; }

 private:
  struct Incident {
    int spring;  // index into springs_
    int sign;    // +1 when this particle is the spring's `a` end, -1 when it is `b`
    int slot;    // block (this particle, other end) in the row
  };

  void add_dropped_spring_terms(const VecX& x, const VecX& v, const VecX& dv, VecX& xhat);

  ClothSpec spec_;
  int p_;
  double h_;
  VecX mass_, x0_;
  std::vector<BucklingSpring> springs_;
  int damped_ = 0;  // springs_[0 .. damped_) carry damping (structural and shear)
  std::vector<int> incident_start_;
  std::vector<Incident> incident_;
  std::vector<std::unique_ptr<Collider>> colliders_;
  std::unique_ptr<PinTrack> pins_;
  std::vector<char> free_;
  std::vector<int> pinned_list_;

  // Per-step work space, sized once.
  std::vector<Vec3> spring_f_;
  std::vector<Mat3> spring_K_, spring_D_;
  BlockSparse3 K_, D_, A_;
  VecX force_, rhs_, dv_, kv_, aw_;
  FilteredPcg pcg_;
  int last_cg_ = 0, last_adjoint_cg_ = 0;
  VecX w_;                                       // last adjoint solution (warm start)
  bool exact_springs_ = false;
  std::vector<VecX> step_dv_, step_x_;  // per step: dv and the x it was taken from (exact spring adjoint)
  VecX xs_;                             // scratch positions for the spring differences
  int last_forward_n_ = -2, last_adjoint_n_ = -2;  // steps of the last solves, -2: none
};

}  // namespace kf

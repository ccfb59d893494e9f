#pragma once
// Choi-Ko cloth stepped by linearised backward Euler (design §4), with two adjoints.
// The forces are the terms listed in cloth_terms.h (cloth_term.h says what a term gives); ClothAssembly sums
// them into f, K, D and A, the energy and the adjoint's products. This file is the step, its energy check
// and its adjoint.
//
// Forward:  A dv = b, A = M - h D - h^2 K, b = h (f + h K v + u), solved by PCG (IC(0) or multigrid) with pinned
//           particles filtered out (Baraff-Witkin); v1 = v + dv, x1 = x + h v1. K is the springs'
//           definite stiffness (compressive transverse part dropped) plus the colliders' normal
//           stiffness, D the spring damping and air drag (the non-symmetric position derivative of spring
//           damping is left out, so A is symmetric and the backward solve reuses the forward PCG).
//           A pinned particle moves to its PinTrack position at n+1 whatever its state.
//           With cloth.control_integration "explicit", u leaves b and v1 = v + dv + h u / m instead.
// Both adjoints solve A w = vhat1 + h xhat1 on the free set (w = 0 on pins), then uhat = h w (explicit
// controls: uhat = h (vhat1 + h xhat1) / m, no solve),
// vhat = M w (0 on pins) and xhat = xhat1 + h Kx^T w + ..., Kx the exact df/dx (springs, spring damping,
// collider curvature, self-contact cross blocks: any bias there is O(h) per step).
//   exact: the transpose of the Jacobian of the step as implemented. It adds the position derivative of
//          the step's matrix met by the step's velocity change, h^2 d/dx[w^T K(x) v1] + h d/dx[w^T D(x) dv]
//          (per spring and contact, analytically: spring_jacobian_derivative, damping_jacobian_v_derivative,
//          Collider::add_definite_stiffness_derivative), with dv from the step's record, and on pinned
//          rows (A w - vhat1)/h, since a pin's v1 = (track - x)/h.
//   swap:  the paper's integrator-swapping approximation: those terms are dropped (and pinned rows keep
//          only A w / h). O(h) per step away from the exact one.
// Steps that gain energy are split (the linearised step invents energy when particles move fast across
// springs or into colliders, and stiff sheets at one step per frame then blow up): a step whose energy
// after, less the work of the controls and the pins, exceeds its energy before by more than 1e-3 of the
// energy it moves is replaced by two half steps, each checked the same way, down to h / 2^max_halvings
// (pins move linearly within a step). The accepted substeps are the step's record; both adjoints walk
// them back, and never decide again, so the exact adjoint stays the Jacobian of the step taken.
// A is recomputed at each substep's start in the backward pass rather than stored.
// PCG starts from the extrapolation of the last steps' solutions when steps come in sequence (WarmStart: n
// after n-1, n-2, n-3 forward, n after n+1, n+2, n+3 backward) and from zero otherwise, so a rollout is the
// same function of its inputs on every run.
#include <cstdint>
#include <memory>
#include <vector>

#include "scene/cloth_spec.h"
#include "sim/cloth/block_sparse.h"
#include "sim/cloth/buckling_spring.h"
#include "sim/cloth/cloth_assembly.h"
#include "sim/cloth/collider.h"
#include "sim/cloth/direct_solve.h"
#include "sim/cloth/filtered_pcg.h"
#include "sim/cloth/pin_track.h"
#include "sim/cloth/warm_start.h"
#include "sim/system.h"

namespace kf {

// What a cloth step records for its adjoint: its accepted substeps in order, each with its depth (length
// h / 2^depth), start state (the step's own for the first one) and velocity change (3p, pins included).
struct ClothRecord final : StepRecord {
  struct Substep {
    int depth = 0;
    double t0 = 0;  // start, as a fraction of the step
    VecX x, v, dv;
  };
  std::vector<Substep> substeps;  // entries [0, count) are this step's; the rest are kept for reuse
  int count = 0;
};

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
  std::unique_ptr<StepRecord> new_record() const override { return std::make_unique<ClothRecord>(); }
  using System::step;
  using System::step_adjoint;
  bool step(int n, const VecX& x, const VecX& v, const VecX& u, VecX& x_next, VecX& v_next,
            StepRecord& record) override;
  void step_adjoint(int n, const VecX& x, const VecX& v, const VecX& u, const StepRecord& record, const VecX& xhat1,
                    const VecX& vhat1, VecX& xhat, VecX& vhat, VecX& uhat) override;
  std::string describe() const override;
  // Over the steps of the forward runs so far (each step counted once, the last time it ran): split_steps,
  // the steps the energy check split, and pcg_iterations_per_step (forward solves, rejected ones included).
  std::vector<std::pair<std::string, double>> run_stats() const override;
  // The PCG warm start of step n (the last forward solutions when they were those of steps n-1, n-2, n-3).
  void save_step_context(int n, VecX& context) const override;
  void restore_step_context(int n, const VecX& context) override;

  // Which steps the energy check split, and how: per step, the depths of its accepted substeps in order
  // (one 0 for an unsplit step). A run records it unless a schedule is held. Held, each step repeats its
  // pattern instead of checking energy (steps past the schedule's end check it), so a rollout is a smooth
  // function of the controls: an optimiser's line search then meets no jump where a check flips.
  using StepSchedule = std::vector<std::vector<std::uint8_t>>;
  const StepSchedule& schedule() const { return recorded_; }
  void hold_schedule(StepSchedule schedule) {
    held_ = std::move(schedule);
    holding_ = true;
  }
  void release_schedule() { holding_ = false; }
  // The same through the System hook (the split pattern type-erased; defined in cloth_split_steps.cpp).
  kf::StepSchedule step_schedule() const override;
  void hold_step_schedule(const kf::StepSchedule& schedule) override;
  void release_step_schedule() override { release_schedule(); }

  void set_adjoint(AdjointKind kind) { adjoint_ = kind; }
  AdjointKind adjoint() const { return adjoint_; }

  // Evaluates forces f and the blocks of K, D and A at (x, v) of step n for a (sub)step of length hs
  // (default h; the forward pass does this). `forces` false leaves f out (the adjoint needs the matrices
  // alone), and force() is then stale.
  void assemble(int n, const VecX& x, const VecX& v, double hs = 0, bool forces = true);
  // Results of the last assemble: f (3p, N), K (N/m), D (N s/m), A (kg), as Eigen matrices (allocate).
  const VecX& force() const { return assembly_.force(); }
  SpMat stiffness_matrix() const;
  SpMat damping_matrix() const;
  SpMat system_matrix() const { return assembly_.matrix().to_sparse(); }

  const ClothSpec& spec() const { return spec_; }
  const std::vector<BucklingSpring>& springs() const { return assembly_.springs().list; }
  int damped_springs() const { return assembly_.springs().damped; }
  int colliders() const { return int(colliders_.size()); }
  bool pinned(int i) const { return !free_[i]; }
  // Substeps of the last forward step (1 when it was not split).
  int last_substeps() const { return last_substeps_; }
  // Energy (J) of a state at step n: free particles' kinetic energy and the terms' (cloth_terms.h):
  // free particles' gravitational energy, every spring's, and the contact energy of the colliders that
  // report it (Collider::energy).
  using Energy = ClothEnergy;
  Energy energy(int n, const VecX& x, const VecX& v) const;
  // The same without the colliders' part (which depends on n).
  Energy state_energy(const VecX& x, const VecX& v) const;
  // PCG iterations of the last forward step (all its solves, a split step's rejected ones too) / of the last
  // backward solve (benchmarks, logs).
  int last_cg_iterations() const { return last_cg_; }
  int last_adjoint_cg_iterations() const { return last_adjoint_cg_; }

 private:
  // One linearised step of length h / 2^depth from fraction t0 of step n; the pins go to their position at
  // fraction t0 + 2^-depth. dv_ holds its velocity change.
  bool linear_step(int n, int depth, double t0, const VecX& x, const VecX& v, const VecX& u, VecX& x_next,
                   VecX& v_next);
  // Takes the (sub)step and, if it gains energy, its two halves instead; appends accepted ones to `rec`.
  bool checked_step(int n, int depth, double t0, const VecX& x, const VecX& v, const VecX& u, VecX& x_next,
                    VecX& v_next, ClothRecord& rec);
  // The (sub)step as the held pattern `pattern` says from its entry cursor_ on: taken whole, or halved.
  bool held_step(int n, int depth, double t0, const VecX& x, const VecX& v, const VecX& u, VecX& x_next,
                 VecX& v_next, ClothRecord& rec, const std::vector<std::uint8_t>& pattern);
  // Records the depths of step n's accepted substeps in recorded_ (none when it failed).
  void record_pattern(int n, bool ok, const ClothRecord& rec);
  // Appends the substep just solved (dv_) to `rec`.
  void accept_substep(int depth, double t0, const VecX& x, const VecX& v, ClothRecord& rec);
  // The adjoint of one linearised substep (see the header comment); adds its uhat to `uhat`.
  void substep_adjoint(int n, double hs, const VecX& x, const VecX& v, const VecX& dv, bool warm, const VecX& xhat1,
                       const VecX& vhat1, VecX& xhat, VecX& vhat, VecX& uhat);
  // Solves the assembled A on the free set (x: prescribed values on pins, warm start on free ones).
  PcgResult solve(const VecX& b, VecX& x, bool warm);
  Energy with_contact_energy(int n, const VecX& x, const VecX& v, Energy e) const;  // e plus the colliders' part
  Energy energy_at_start(int n, const VecX& x, const VecX& v);
  void remember_energy(const VecX& x, const VecX& v, const Energy& e);
  // Work (J) of the control u on the free particles and of the pins on their springs from x0 to x1.
  // `control`: whether u's work counts (an explicit control's kick is outside the checked solve).
  double external_work(const VecX& u, const VecX& x0, const VecX& x1, bool control) const;

  ClothSpec spec_;
  int p_;
  double h_;
  VecX x0_;
  std::vector<std::unique_ptr<Collider>> colliders_;  // before assembly_, whose contact term reads them
  ClothAssembly assembly_;                            // the force terms, f, K, D and A
  VecX mass_;
  std::unique_ptr<PinTrack> pins_;
  std::vector<char> free_;
  std::vector<int> pinned_list_;
  std::vector<int> pinned_springs_;  // springs with a pinned end (the pins' work)

  // Per-step work space, sized once.
  VecX rhs_, dv_;
  WarmStart forward_start_{+1};  // the guess of each step's velocity change
  FilteredPcg pcg_;
  FilteredDirect direct_;  // cloth.solver = "direct"
  bool direct_solve_ = false, direct_ok_ = false;
  int last_cg_ = 0, last_adjoint_cg_ = 0;
  VecX w_;                       // the adjoint solve's solution
  WarmStart adjoint_start_{-1};  // its guess
  std::vector<VecX> split_x_, split_v_;  // per depth: the state between two halves of a split step
  VecX adj_x_, adj_v_, adj_u_;           // adjoint of one substep (walking split steps back)
  int last_substeps_ = 0;
  std::vector<int> step_substeps_, step_cg_;  // per step n of the runs so far (0: not run)
  StepSchedule recorded_, held_;
  bool holding_ = false;
  std::size_t cursor_ = 0;  // the next entry of the held step's pattern
  VecX energy_x_, energy_v_;  // the state whose collider-free energy is cached_energy_
  VecX solved_x_, solved_v_;  // with explicit controls: a substep's end without the kick, which the check measures
  Energy cached_energy_;
  VecX c_;   // v + dv of the step being walked back
  AdjointKind adjoint_ = AdjointKind::kExact;
};

}  // namespace kf

#pragma once
// How the optimisation variables z become control forces: one force per particle per step (paper),
// one per particle per frame held over its substeps (Stuyck ch. 8), the initial velocities only, one
// initial linear and angular velocity for the whole body (a thrown sheet needs six numbers, not 3p), or
// initial velocities interpolated from a 3 x 3 lattice laid over the sheet (smooth: they bend the throw
// without exciting the stiff springs between neighbours, which per-particle velocities do), or per-frame
// forces interpolated from the same lattice (a coarse stage before per-particle forces: its directions move
// the sheet as a whole, where a per-particle gradient in contact is ruled by the few particles touching).
// Ground-bound (planar) systems get no y components.
#include <array>
#include <utility>
#include <vector>

#include "core/types.h"
#include "scene/objective_spec.h"
#include "scene/time_spec.h"

namespace kf {

class Controls {
 public:
  // dof = 3p; x0_scene, v0_scene: the scene's initial state (the reference for initial-velocity control).
  Controls(const ControlSpec& spec, const TimeSpec& time, int particles, bool planar, const VecX& x0_scene,
           const VecX& v0_scene);

  int size() const { return rigid_ ? 6 : blocks_ * block_size(); }
  // Force controls (per step, per frame, per frame on the lattice), not initial velocities.
  bool forces() const { return kind_ != ControlKind::kInitialVelocity; }
  // The scene's kind (its name: kind_name(), for logs and reports).
  ControlKind kind() const { return name_; }
  const char* kind_name() const { return control_kind_name(name_); }
  // Initial velocities (per particle, rigid or on the lattice), not forces over time.
  bool initial() const {
    return name_ == ControlKind::kInitialVelocity || name_ == ControlKind::kInitialRigidVelocity ||
           name_ == ControlKind::kInitialLatticeVelocity;
  }
  // The starting point of the optimisation: no force, or the scene's initial velocities.
  VecX initial_guess() const;
  // z (size()) -> initial velocities v0 (3p) and per-step forces U (N entries of 3p, resized here).
  void expand(const VecX& z, VecX& v0, std::vector<VecX>& U) const;
  // Chain rule back: dphi/dU and dphi/dv0 -> dphi/dz (overwrites dz).
  void gather(const std::vector<VecX>& dU, const VecX& dv0, VecX& dz) const;
  // Force controls as one force per particle for each of their blocks (steps or frames): lattice forces
  // spread over the particles; other kinds unchanged.
  VecX per_particle_forces(const VecX& z) const;
  // Carries controls made for `from` (another substep count) whose forces began at frame `from_frame`
  // over to this parameterisation: initial-velocity controls are unchanged; force controls `z` come one
  // force per particle per block (per_particle_forces) and per-step forces are held over the nearest
  // coarse step; frames the earlier controls did not reach get no force, frames they reached before this
  // one's first frame are dropped (a window grown backwards starts where the last one ended). Lattice
  // forces are then the least-squares fit of each block.
  VecX remap_from(const VecX& z, const TimeSpec& from, int from_frame) const;
  // The first frame with a force (controls.from_frame, clamped; 0 for initial velocities).
  int first_frame() const { return first_step_ / substeps_; }
  // One step at a time (no per-step storage): the force of step n (3p, resized here) and the chain
  // rule of one step's dphi/du_n (3p) added into dz (size()). Zero / nothing for initial velocities.
  void force_at(const VecX& z, int n, VecX& u) const;
  void add_step_gradient(int n, const VecX& uhat, VecX& dz) const;
  // The first step whose force is a control (0 for initial-velocity controls, which need the whole adjoint).
  int first_step() const { return kind_ == ControlKind::kInitialVelocity ? 0 : first_step_; }
  // The initial velocities z gives (3p).
  void initial_velocity(const VecX& z, VecX& v0) const;
  // The initial-velocity controls (size()) that give v0 (3p), e.g. a rigid throw's velocities carried into
  // the next stage: exact for per-particle controls, the least-squares fit for a lattice. Not for rigid.
  VecX from_initial_velocity(const VecX& v0) const;
  // dphi/dv0 -> dphi/dz for initial-velocity control, added into dz (nothing for force controls).
  void gather_initial_velocity(const VecX& dv0, VecX& dz) const;
  // Control effort ½α∫‖u‖²dt (forces), ½α‖v0 − v0_scene‖² (initial velocities) or ½α‖(Δv, ω)‖² (rigid);
  // adds its gradient.
  double effort(const VecX& z, VecX& dz) const;

 private:
  ControlKind name_, kind_;  // the scene's kind; how it behaves (rigid is a kind of initial_velocity, lattice
                             // forces of per_frame)
  double alpha_;
  int steps_, substeps_, frames_, particles_, blocks_;
  double h_;
  int first_step_ = 0;       // the first step with a force (controls' from_frame)
  std::vector<int> comps_;  // which of x, y, z are controlled
  // The force block step n reads (-1: before first_step_, no force).
  int block_of(int n) const;
  // Variables per block: one per node of the lattice or per particle, times the controlled components.
  int block_size() const { return (lattice_ ? kLatticeNodes : particles_) * int(comps_.size()); }
  // One block's values per particle (3p, controlled components only; others untouched) and the chain rule
  // back (added into the block).
  void spread(const double* block, VecX& per_particle) const;
  void collect(const VecX& per_particle, double* block) const;
  // The block that spreads closest (least squares) to per-particle values (3p); the lattice only.
  void fit(const VecX& per_particle, double* block) const;
  VecX v0_scene_;
  // Rigid initial velocity: z = (Δv, ω), v0_i = v0_scene_i + Δv + ω × (x0_i − c); arms_ holds x0_i − c.
  bool rigid_ = false;
  VecX arms_;
  void rigid_velocity(const VecX& z, VecX& v0) const;
  void rigid_gather(const VecX& dv0, VecX& dz) const;
  // Lattice: v0_i = v0_scene_i + Σ_k w_ik z_k (or a frame's force u_i = Σ_k w_ik z_k), bilinear over the
  // kLatticeSide² nodes of a grid spanning the initial sheet's two widest principal axes; each particle's
  // four (node, weight).
  static constexpr int kLatticeSide = 3, kLatticeNodes = kLatticeSide * kLatticeSide;
  bool lattice_ = false;
  std::vector<std::array<std::pair<int, double>, 4>> lattice_weights_;
  void lay_lattice(const VecX& x0_scene);
};

}  // namespace kf

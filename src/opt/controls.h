#pragma once
// How the optimisation variables z become control forces or initial velocities. A kind is a timing (the
// initial velocities; one force per step, as in the paper; one per frame held over its substeps, Stuyck
// ch. 8) and a basis (control_basis.h: per particle; a 3 x 3 lattice laid over the sheet, smooth, so it
// bends a throw or moves a sheet in contact as a whole without exciting the stiff springs between
// neighbours; a rigid linear and angular velocity, six numbers for a thrown sheet instead of 3p). The
// timing is decided here, each basis in its own struct. Ground-bound (planar) systems get no y components.
#include <variant>
#include <vector>

#include "core/types.h"
#include "opt/control_basis.h"
#include "scene/control_kind.h"
#include "scene/time_spec.h"

namespace kf {

class Controls {
 public:
  // dof = 3p; x0_scene, v0_scene: the scene's initial state (the reference for initial-velocity control).
  Controls(const ControlSpec& spec, const TimeSpec& time, int particles, bool planar, const VecX& x0_scene,
           const VecX& v0_scene);

  int size() const { return blocks_ * block_size(); }
  // The two axes of the kind (scene/objective_spec.h).
  ControlTiming timing() const { return timing_; }
  ControlBasis basis() const { return control_basis(kind_); }
  // Force controls (per step, per frame, per frame on the lattice), not initial velocities.
  bool forces() const { return timing_ != ControlTiming::kInitial; }
  // The scene's kind (its name: kind_name(), for logs and reports).
  ControlKind kind() const { return kind_; }
  const char* kind_name() const { return control_kind_name(kind_); }
  // Initial velocities (per particle, rigid or on the lattice), not forces over time.
  bool initial() const { return timing_ == ControlTiming::kInitial; }
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
  int first_step() const { return first_step_; }
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
  ControlKind kind_;  // the scene's
  ControlTiming timing_;
  std::vector<int> comps_;  // which of x, y, z are controlled
  AnyControlBasis basis_;  // what one block sets (control_basis.h)
  double alpha_;
  int steps_, substeps_, frames_, particles_, blocks_;
  double h_;
  int first_step_ = 0;  // the first step with a force (controls' from_frame; 0 for initial velocities)
  VecX v0_scene_;
  // The force block step n reads (-1: before first_step_, no force).
  int block_of(int n) const;
  int block_size() const {
    return std::visit([](const auto& b) { return b.size(); }, basis_);
  }
  // One block's values per particle (added into 3p) and the chain rule back (added into the block).
  void spread(const double* block, VecX& per_particle) const {
    std::visit([&](const auto& b) { b.spread(block, per_particle); }, basis_);
  }
  void collect(const VecX& per_particle, double* block) const {
    std::visit([&](const auto& b) { b.collect(per_particle, block); }, basis_);
  }
  void fit(const VecX& per_particle, double* block) const {
    std::visit([&](const auto& b) { b.fit(per_particle, block); }, basis_);
  }
  // Per-particle initial velocities are the velocities themselves; lattice and rigid ones change the scene's.
  bool per_particle() const { return std::holds_alternative<ParticleBasis>(basis_); }
};

}  // namespace kf

#include "opt/controls.h"

#include <algorithm>
#include <stdexcept>

namespace kf {

Controls::Controls(const ControlSpec& spec, const TimeSpec& time, int particles, bool planar, const VecX& x0_scene,
                   const VecX& v0_scene)
    : kind_(spec.kind),
      timing_(control_timing(spec.kind)),
      comps_(planar ? std::vector<int>{0, 2} : std::vector<int>{0, 1, 2}),
      basis_(make_control_basis(control_basis(spec.kind), particles, comps_, x0_scene)),
      alpha_(spec.alpha),
      steps_(time.steps()),
      substeps_(time.substeps),
      frames_(time.frames),
      particles_(particles),
      h_(time.h()),
      v0_scene_(v0_scene) {
  const int from = std::clamp(spec.from_frame, 0, std::max(0, time.frames - 1));
  switch (timing_) {
    case ControlTiming::kInitial: first_step_ = 0, blocks_ = 1; break;
    case ControlTiming::kPerStep: first_step_ = from * substeps_, blocks_ = steps_ - first_step_; break;
    case ControlTiming::kPerFrame: first_step_ = from * substeps_, blocks_ = time.frames - from; break;
  }
}

int Controls::block_of(int n) const {
  if (n < first_step_) return -1;
  return timing_ == ControlTiming::kPerStep ? n - first_step_ : (n - first_step_) / substeps_;
}

VecX Controls::initial_guess() const {
  VecX z = VecX::Zero(size());
  if (initial() && per_particle()) fit(v0_scene_, z.data());
  return z;
}

void Controls::expand(const VecX& z, VecX& v0, std::vector<VecX>& U) const {
  const int dof = 3 * particles_;
  U.resize(steps_);
  for (auto& u : U) {
    if (u.size() != dof) u.resize(dof);
    u.setZero();
  }
  initial_velocity(z, v0);
  if (initial()) return;
  for (int n = first_step_; n < steps_; ++n) spread(z.data() + long(block_of(n)) * block_size(), U[n]);
}

void Controls::gather(const std::vector<VecX>& dU, const VecX& dv0, VecX& dz) const {
  dz.setZero(size());
  if (initial()) return gather_initial_velocity(dv0, dz);
  for (int n = first_step_; n < steps_; ++n) collect(dU[n], dz.data() + long(block_of(n)) * block_size());
}

VecX Controls::per_particle_forces(const VecX& z) const {
  if (per_particle() || !forces()) return z;
  const int nc = int(comps_.size()), stride = particles_ * nc;
  VecX out(long(blocks_) * stride), u(3 * particles_);
  for (int b = 0; b < blocks_; ++b) {
    u.setZero();
    spread(z.data() + long(b) * block_size(), u);
    for (int i = 0; i < particles_; ++i)
      for (int c = 0; c < nc; ++c) out[long(b) * stride + i * nc + c] = u[3 * i + comps_[c]];
  }
  return out;
}

VecX Controls::remap_from(const VecX& z, const TimeSpec& from, int from_frame) const {
  if (initial()) return z;
  const int from_first = std::clamp(from_frame, 0, std::max(0, frames_ - 1)) * from.substeps;
  const int nc = int(comps_.size()), stride = particles_ * nc;
  VecX out = z;
  if (from.substeps != substeps_ || from_first != first_step_) {
    // The earlier controls' block holding step m of their discretisation (-1: none).
    const auto from_block = [&](int m) {
      if (m < from_first) return -1;
      return timing_ == ControlTiming::kPerStep ? m - from_first : (m - from_first) / from.substeps;
    };
    out = VecX::Zero(long(blocks_) * stride);
    for (int n = first_step_; n < steps_; ++n) {
      const int m = std::min(from.steps() - 1, int((long(n) * from.substeps) / substeps_));
      const int b = from_block(m);
      if (b < 0 || long(b + 1) * stride > z.size()) continue;
      out.segment(long(block_of(n)) * stride, stride) = z.segment(long(b) * stride, stride);
    }
  }
  if (per_particle() || out.size() != long(blocks_) * stride) return out;  // a size mismatch is the caller's to report
  VecX fitted(size()), u = VecX::Zero(3 * particles_);
  for (int b = 0; b < blocks_; ++b) {
    for (int i = 0; i < particles_; ++i)
      for (int c = 0; c < nc; ++c) u[3 * i + comps_[c]] = out[long(b) * stride + i * nc + c];
    fit(u, fitted.data() + long(b) * block_size());
  }
  return fitted;
}

void Controls::force_at(const VecX& z, int n, VecX& u) const {
  const int dof = 3 * particles_;
  if (u.size() != dof) u.resize(dof);
  u.setZero();
  const int b = block_of(n);
  if (initial() || b < 0) return;
  spread(z.data() + long(b) * block_size(), u);
}

void Controls::add_step_gradient(int n, const VecX& uhat, VecX& dz) const {
  const int b = block_of(n);
  if (initial() || b < 0) return;
  collect(uhat, dz.data() + long(b) * block_size());
}

void Controls::initial_velocity(const VecX& z, VecX& v0) const {
  v0 = v0_scene_;
  if (!initial()) return;
  if (!per_particle()) return spread(z.data(), v0);
  const int nc = int(comps_.size());
  for (int i = 0; i < particles_; ++i)
    for (int c = 0; c < nc; ++c) v0[3 * i + comps_[c]] = z[i * nc + c];
}

VecX Controls::from_initial_velocity(const VecX& v0) const {
  if (!initial() || std::holds_alternative<RigidBasis>(basis_))
    throw std::logic_error("Controls::from_initial_velocity: only for per-particle or lattice initial velocities");
  VecX z(size());
  if (per_particle()) fit(v0, z.data());
  else fit(v0 - v0_scene_, z.data());
  return z;
}

void Controls::gather_initial_velocity(const VecX& dv0, VecX& dz) const {
  if (initial()) collect(dv0, dz.data());
}

double Controls::effort(const VecX& z, VecX& dz) const {
  if (initial()) {
    const VecX d = z - initial_guess();
    dz += alpha_ * d;
    return 0.5 * alpha_ * d.squaredNorm();
  }
  // Time-integral of ‖u‖²: a frame's force acts for `substeps` steps of length h.
  const double dt = timing_ == ControlTiming::kPerStep ? h_ : h_ * substeps_;
  if (per_particle()) {
    dz += alpha_ * dt * z;
    return 0.5 * alpha_ * dt * z.squaredNorm();
  }
  // Forces on a coarser basis: the effort of the forces the particles feel, ½α dt Σ_b ‖W z_b‖² (as the
  // per-particle stage after it counts them), gradient α dt Wᵀ W z_b.
  double sum = 0;
  VecX u(3 * particles_);
  for (int b = 0; b < blocks_; ++b) {
    u.setZero();
    spread(z.data() + long(b) * block_size(), u);
    sum += u.squaredNorm();
    u *= alpha_ * dt;
    collect(u, dz.data() + long(b) * block_size());
  }
  return 0.5 * alpha_ * dt * sum;
}

}  // namespace kf

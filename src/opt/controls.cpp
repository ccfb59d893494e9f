#include "opt/controls.h"

#include <algorithm>
#include <stdexcept>

#include <Eigen/Eigenvalues>  // the sheet's principal axes
#include <Eigen/Geometry>     // cross products

namespace kf {

Controls::Controls(const ControlSpec& spec, const TimeSpec& time, int particles, bool planar, const VecX& x0_scene,
                   const VecX& v0_scene)
    : name_(spec.kind), kind_(spec.kind), alpha_(spec.alpha), steps_(time.steps()), substeps_(time.substeps), frames_(time.frames),
      particles_(particles),
      h_(time.h()), v0_scene_(v0_scene) {
  comps_ = planar ? std::vector<int>{0, 2} : std::vector<int>{0, 1, 2};
  if (kind_ == ControlKind::kPerFrameLattice || kind_ == ControlKind::kInitialLatticeVelocity) {
    lattice_ = true;
    kind_ = kind_ == ControlKind::kPerFrameLattice ? ControlKind::kPerFrame : ControlKind::kInitialVelocity;
    lay_lattice(x0_scene);
  }
  const int from = std::clamp(spec.from_frame, 0, std::max(0, time.frames - 1));
  first_step_ = kind_ == ControlKind::kPerStep || kind_ == ControlKind::kPerFrame ? from * substeps_ : 0;
  blocks_ = kind_ == ControlKind::kPerStep ? steps_ - first_step_ : kind_ == ControlKind::kPerFrame ? time.frames - from : 1;
  if (kind_ == ControlKind::kInitialRigidVelocity) {
    rigid_ = true;
    kind_ = ControlKind::kInitialVelocity;  // everywhere else it behaves as initial-velocity control
    Vec3 c = Vec3::Zero();
    for (int i = 0; i < particles_; ++i) c += x0_scene.segment<3>(3 * i);
    c /= std::max(1, particles_);
    arms_.resize(3 * particles_);
    for (int i = 0; i < particles_; ++i) arms_.segment<3>(3 * i) = x0_scene.segment<3>(3 * i) - c;
  }
}

void Controls::lay_lattice(const VecX& x0_scene) {
  Vec3 c = Vec3::Zero();
  for (int i = 0; i < particles_; ++i) c += x0_scene.segment<3>(3 * i);
  c /= std::max(1, particles_);
  Mat3 cov = Mat3::Zero();
  for (int i = 0; i < particles_; ++i) {
    const Vec3 r = x0_scene.segment<3>(3 * i) - c;
    cov += r * r.transpose();
  }
  // Eigenvalues ascending: the last two columns are the sheet's plane (a crumpled start: its widest extent).
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(cov);
  const Vec3 axes[2] = {eig.eigenvectors().col(2), eig.eigenvectors().col(1)};
  std::vector<double> coord[2];
  double lo[2], hi[2];
  for (int a = 0; a < 2; ++a) {
    coord[a].resize(particles_);
    for (int i = 0; i < particles_; ++i) coord[a][i] = (x0_scene.segment<3>(3 * i) - c).dot(axes[a]);
    lo[a] = particles_ ? *std::min_element(coord[a].begin(), coord[a].end()) : 0;
    hi[a] = particles_ ? *std::max_element(coord[a].begin(), coord[a].end()) : 0;
  }
  constexpr int n = kLatticeSide - 1;  // cells per side
  lattice_weights_.resize(particles_);
  for (int i = 0; i < particles_; ++i) {
    int cell[2];
    double t[2];
    for (int a = 0; a < 2; ++a) {
      const double u = hi[a] > lo[a] ? (coord[a][i] - lo[a]) / (hi[a] - lo[a]) * n : 0.0;
      cell[a] = std::clamp(int(u), 0, n - 1);
      t[a] = std::clamp(u - cell[a], 0.0, 1.0);
    }
    const int k = cell[1] * kLatticeSide + cell[0];
    lattice_weights_[i] = {{{k, (1 - t[0]) * (1 - t[1])},
                            {k + 1, t[0] * (1 - t[1])},
                            {k + kLatticeSide, (1 - t[0]) * t[1]},
                            {k + kLatticeSide + 1, t[0] * t[1]}}};
  }
}

void Controls::spread(const double* block, VecX& per_particle) const {
  const int nc = int(comps_.size());
  for (int i = 0; i < particles_; ++i)
    for (int c = 0; c < nc; ++c) {
      double& out = per_particle[3 * i + comps_[c]];
      if (!lattice_) {
        out += block[i * nc + c];
        continue;
      }
      for (const auto& [k, w] : lattice_weights_[i]) out += w * block[k * nc + c];
    }
}

void Controls::collect(const VecX& per_particle, double* block) const {
  const int nc = int(comps_.size());
  for (int i = 0; i < particles_; ++i)
    for (int c = 0; c < nc; ++c) {
      const double g = per_particle[3 * i + comps_[c]];
      if (!lattice_) {
        block[i * nc + c] += g;
        continue;
      }
      for (const auto& [k, w] : lattice_weights_[i]) block[k * nc + c] += w * g;
    }
}

void Controls::fit(const VecX& per_particle, double* block) const {
  // Least squares: (W^T W) z_c = W^T values_c for each component c.
  const int nc = int(comps_.size());
  Eigen::Matrix<double, kLatticeNodes, kLatticeNodes> normal = Eigen::Matrix<double, kLatticeNodes, kLatticeNodes>::Zero();
  Eigen::Matrix<double, kLatticeNodes, Eigen::Dynamic> rhs = Eigen::Matrix<double, kLatticeNodes, Eigen::Dynamic>::Zero(kLatticeNodes, nc);
  for (int i = 0; i < particles_; ++i)
    for (const auto& [k, w] : lattice_weights_[i]) {
      for (const auto& [l, wl] : lattice_weights_[i]) normal(k, l) += w * wl;
      for (int c = 0; c < nc; ++c) rhs(k, c) += w * per_particle[3 * i + comps_[c]];
    }
  normal.diagonal().array() += 1e-12 * std::max(1.0, normal.trace());  // a node no particle reaches gets 0
  const Eigen::Matrix<double, kLatticeNodes, Eigen::Dynamic> sol = normal.ldlt().solve(rhs);
  for (int k = 0; k < kLatticeNodes; ++k)
    for (int c = 0; c < nc; ++c) block[k * nc + c] = sol(k, c);
}

int Controls::block_of(int n) const {
  if (n < first_step_) return -1;
  return kind_ == ControlKind::kPerStep ? n - first_step_ : (n - first_step_) / substeps_;
}

void Controls::rigid_velocity(const VecX& z, VecX& v0) const {
  const Vec3 dv = z.head<3>(), w = z.tail<3>();
  v0 = v0_scene_;
  for (int i = 0; i < particles_; ++i) {
    Vec3 vi = dv + w.cross(Vec3(arms_.segment<3>(3 * i)));
    for (int c : comps_) v0[3 * i + c] += vi[c];
  }
}

// d(ω × r)/dω applied transposed: Σ r × g.
void Controls::rigid_gather(const VecX& dv0, VecX& dz) const {
  Vec3 gv = Vec3::Zero(), gw = Vec3::Zero();
  for (int i = 0; i < particles_; ++i) {
    Vec3 g = Vec3::Zero();
    for (int c : comps_) g[c] = dv0[3 * i + c];
    gv += g;
    gw += Vec3(arms_.segment<3>(3 * i)).cross(g);
  }
  dz.head<3>() += gv;
  dz.tail<3>() += gw;
}

VecX Controls::initial_guess() const {
  VecX z = VecX::Zero(size());
  if (kind_ == ControlKind::kInitialVelocity && !rigid_ && !lattice_) {
    const int nc = int(comps_.size());
    for (int i = 0; i < particles_; ++i)
      for (int c = 0; c < nc; ++c) z[i * nc + c] = v0_scene_[3 * i + comps_[c]];
  }
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
  if (kind_ == ControlKind::kInitialVelocity) return;
  for (int n = first_step_; n < steps_; ++n) spread(z.data() + long(block_of(n)) * block_size(), U[n]);
}

void Controls::gather(const std::vector<VecX>& dU, const VecX& dv0, VecX& dz) const {
  dz.setZero(size());
  if (kind_ == ControlKind::kInitialVelocity) return gather_initial_velocity(dv0, dz);
  for (int n = first_step_; n < steps_; ++n) collect(dU[n], dz.data() + long(block_of(n)) * block_size());
}

VecX Controls::per_particle_forces(const VecX& z) const {
  if (!lattice_ || !forces()) return z;
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
  if (kind_ == ControlKind::kInitialVelocity) return z;
  const int from_first = std::clamp(from_frame, 0, std::max(0, frames_ - 1)) * from.substeps;
  const int nc = int(comps_.size()), stride = particles_ * nc;
  VecX out = z;
  if (from.substeps != substeps_ || from_first != first_step_) {
    // The earlier controls' block holding step m of their discretisation (-1: none).
    const auto from_block = [&](int m) {
      if (m < from_first) return -1;
      return kind_ == ControlKind::kPerStep ? m - from_first : (m - from_first) / from.substeps;
    };
    out = VecX::Zero(long(blocks_) * stride);
    for (int n = first_step_; n < steps_; ++n) {
      const int m = std::min(from.steps() - 1, int((long(n) * from.substeps) / substeps_));
      const int b = from_block(m);
      if (b < 0 || long(b + 1) * stride > z.size()) continue;
      out.segment(long(block_of(n)) * stride, stride) = z.segment(long(b) * stride, stride);
    }
  }
  if (!lattice_ || out.size() != long(blocks_) * stride) return out;  // a size mismatch is the caller's to report
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
  if (kind_ == ControlKind::kInitialVelocity || b < 0) return;
  spread(z.data() + long(b) * block_size(), u);
}

void Controls::add_step_gradient(int n, const VecX& uhat, VecX& dz) const {
  const int b = block_of(n);
  if (kind_ == ControlKind::kInitialVelocity || b < 0) return;
  collect(uhat, dz.data() + long(b) * block_size());
}

void Controls::initial_velocity(const VecX& z, VecX& v0) const {
  const int nc = int(comps_.size());
  v0 = v0_scene_;
  if (kind_ != ControlKind::kInitialVelocity) return;
  if (rigid_) return rigid_velocity(z, v0);
  if (lattice_) return spread(z.data(), v0);
  for (int i = 0; i < particles_; ++i)
    for (int c = 0; c < nc; ++c) v0[3 * i + comps_[c]] = z[i * nc + c];
}

VecX Controls::from_initial_velocity(const VecX& v0) const {
  if (kind_ != ControlKind::kInitialVelocity || rigid_)
    throw std::logic_error("Controls::from_initial_velocity: only for per-particle or lattice initial velocities");
  const int nc = int(comps_.size());
  VecX z(size());
  if (lattice_) {
    fit(v0 - v0_scene_, z.data());
    return z;
  }
  for (int i = 0; i < particles_; ++i)
    for (int c = 0; c < nc; ++c) z[i * nc + c] = v0[3 * i + comps_[c]];
  return z;
}

void Controls::gather_initial_velocity(const VecX& dv0, VecX& dz) const {
  const int nc = int(comps_.size());
  if (kind_ != ControlKind::kInitialVelocity) return;
  if (rigid_) return rigid_gather(dv0, dz);
  if (lattice_) return collect(dv0, dz.data());
  for (int i = 0; i < particles_; ++i)
    for (int c = 0; c < nc; ++c) dz[i * nc + c] += dv0[3 * i + comps_[c]];
}

double Controls::effort(const VecX& z, VecX& dz) const {
  if (kind_ == ControlKind::kInitialVelocity) {
    const VecX d = z - initial_guess();
    dz += alpha_ * d;
    return 0.5 * alpha_ * d.squaredNorm();
  }
  // Time-integral of ‖u‖²: a frame's force acts for `substeps` steps of length h.
  const double dt = kind_ == ControlKind::kPerStep ? h_ : h_ * substeps_;
  if (!lattice_) {
    dz += alpha_ * dt * z;
    return 0.5 * alpha_ * dt * z.squaredNorm();
  }
  // Lattice forces: the effort of the forces the particles feel, ½α dt Σ_b ‖W z_b‖² (as the per-particle
  // stage after it counts them), gradient α dt Wᵀ W z_b.
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

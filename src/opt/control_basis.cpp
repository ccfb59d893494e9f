#include "opt/control_basis.h"

#include <algorithm>
#include <stdexcept>

#include <Eigen/Eigenvalues>  // the sheet's principal axes
#include <Eigen/Geometry>     // cross products

namespace kf {

void ParticleBasis::spread(const double* block, VecX& per_particle) const {
  const int nc = int(comps.size());
  for (int i = 0; i < particles; ++i)
    for (int c = 0; c < nc; ++c) per_particle[3 * i + comps[c]] += block[i * nc + c];
}

void ParticleBasis::collect(const VecX& per_particle, double* block) const {
  const int nc = int(comps.size());
  for (int i = 0; i < particles; ++i)
    for (int c = 0; c < nc; ++c) block[i * nc + c] += per_particle[3 * i + comps[c]];
}

void ParticleBasis::fit(const VecX& per_particle, double* block) const {
  const int nc = int(comps.size());
  for (int i = 0; i < particles; ++i)
    for (int c = 0; c < nc; ++c) block[i * nc + c] = per_particle[3 * i + comps[c]];
}

LatticeBasis::LatticeBasis(int particles, std::vector<int> comps, const VecX& x0)
    : particles(particles), comps(std::move(comps)) {
  Vec3 c = Vec3::Zero();
  for (int i = 0; i < particles; ++i) c += x0.segment<3>(3 * i);
  c /= std::max(1, particles);
  Mat3 cov = Mat3::Zero();
  for (int i = 0; i < particles; ++i) {
    const Vec3 r = x0.segment<3>(3 * i) - c;
    cov += r * r.transpose();
  }
  // Eigenvalues ascending: the last two columns are the sheet's plane (a crumpled start: its widest extent).
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(cov);
  const Vec3 axes[2] = {eig.eigenvectors().col(2), eig.eigenvectors().col(1)};
  std::vector<double> coord[2];
  double lo[2], hi[2];
  for (int a = 0; a < 2; ++a) {
    coord[a].resize(particles);
    for (int i = 0; i < particles; ++i) coord[a][i] = (x0.segment<3>(3 * i) - c).dot(axes[a]);
    lo[a] = particles ? *std::min_element(coord[a].begin(), coord[a].end()) : 0;
    hi[a] = particles ? *std::max_element(coord[a].begin(), coord[a].end()) : 0;
  }
  constexpr int n = kSide - 1;  // cells per side
  weights.resize(particles);
  for (int i = 0; i < particles; ++i) {
    int cell[2];
    double t[2];
    for (int a = 0; a < 2; ++a) {
      const double u = hi[a] > lo[a] ? (coord[a][i] - lo[a]) / (hi[a] - lo[a]) * n : 0.0;
      cell[a] = std::clamp(int(u), 0, n - 1);
      t[a] = std::clamp(u - cell[a], 0.0, 1.0);
    }
    const int k = cell[1] * kSide + cell[0];
    weights[i] = {{{k, (1 - t[0]) * (1 - t[1])},
                   {k + 1, t[0] * (1 - t[1])},
                   {k + kSide, (1 - t[0]) * t[1]},
                   {k + kSide + 1, t[0] * t[1]}}};
  }
}

void LatticeBasis::spread(const double* block, VecX& per_particle) const {
  const int nc = int(comps.size());
  for (int i = 0; i < particles; ++i)
    for (int c = 0; c < nc; ++c) {
      double& out = per_particle[3 * i + comps[c]];
      for (const auto& [k, w] : weights[i]) out += w * block[k * nc + c];
    }
}

void LatticeBasis::collect(const VecX& per_particle, double* block) const {
  const int nc = int(comps.size());
  for (int i = 0; i < particles; ++i)
    for (int c = 0; c < nc; ++c) {
      const double g = per_particle[3 * i + comps[c]];
      for (const auto& [k, w] : weights[i]) block[k * nc + c] += w * g;
    }
}

void LatticeBasis::fit(const VecX& per_particle, double* block) const {
  // Least squares: (W^T W) z_c = W^T values_c for each component c.
  const int nc = int(comps.size());
  Eigen::Matrix<double, kNodes, kNodes> normal = Eigen::Matrix<double, kNodes, kNodes>::Zero();
  Eigen::Matrix<double, kNodes, Eigen::Dynamic> rhs = Eigen::Matrix<double, kNodes, Eigen::Dynamic>::Zero(kNodes, nc);
  for (int i = 0; i < particles; ++i)
    for (const auto& [k, w] : weights[i]) {
      for (const auto& [l, wl] : weights[i]) normal(k, l) += w * wl;
      for (int c = 0; c < nc; ++c) rhs(k, c) += w * per_particle[3 * i + comps[c]];
    }
  normal.diagonal().array() += 1e-12 * std::max(1.0, normal.trace());  // a node no particle reaches gets 0
  const Eigen::Matrix<double, kNodes, Eigen::Dynamic> sol = normal.ldlt().solve(rhs);
  for (int k = 0; k < kNodes; ++k)
    for (int c = 0; c < nc; ++c) block[k * nc + c] = sol(k, c);
}

RigidBasis::RigidBasis(int particles, std::vector<int> comps, const VecX& x0)
    : particles(particles), comps(std::move(comps)) {
  Vec3 c = Vec3::Zero();
  for (int i = 0; i < particles; ++i) c += x0.segment<3>(3 * i);
  c /= std::max(1, particles);
  arms.resize(3 * particles);
  for (int i = 0; i < particles; ++i) arms.segment<3>(3 * i) = x0.segment<3>(3 * i) - c;
}

void RigidBasis::spread(const double* block, VecX& per_particle) const {
  const Vec3 dv(block[0], block[1], block[2]), w(block[3], block[4], block[5]);
  for (int i = 0; i < particles; ++i) {
    const Vec3 vi = dv + w.cross(Vec3(arms.segment<3>(3 * i)));
    for (int c : comps) per_particle[3 * i + c] += vi[c];
  }
}

// d(ω × r)/dω applied transposed: Σ r × g.
void RigidBasis::collect(const VecX& per_particle, double* block) const {
  Vec3 gv = Vec3::Zero(), gw = Vec3::Zero();
  for (int i = 0; i < particles; ++i) {
    Vec3 g = Vec3::Zero();
    for (int c : comps) g[c] = per_particle[3 * i + c];
    gv += g;
    gw += Vec3(arms.segment<3>(3 * i)).cross(g);
  }
  for (int k = 0; k < 3; ++k) block[k] += gv[k], block[3 + k] += gw[k];
}

void RigidBasis::fit(const VecX&, double*) const {
  throw std::logic_error("RigidBasis::fit: a rigid motion is not fitted to per-particle values");
}

AnyControlBasis make_control_basis(ControlBasis b, int particles, std::vector<int> comps, const VecX& x0) {
  switch (b) {
    case ControlBasis::kPerParticle: return ParticleBasis(particles, std::move(comps));
    case ControlBasis::kLattice: return LatticeBasis(particles, std::move(comps), x0);
    case ControlBasis::kRigid: return RigidBasis(particles, std::move(comps), x0);
  }
  throw std::logic_error("make_control_basis: unknown basis");
}

}  // namespace kf

#include "opt/projection_metric.h"

#include <algorithm>
#include <cmath>

namespace kf {

namespace {

// k(i, j) = 1 + (x_i − c)·(x_j − c) / R² + exp(−‖x_i − x_j‖² / (2σ²)) over the sheet's initial positions (c its
// centroid, R its RMS radius, σ = R / 2): the affine part holds a rigid Δv + ω × r (or a uniform push and a
// turn), the Gaussian a bend.
Eigen::MatrixXd smooth_kernel(const VecX& x0) {
  const long p = x0.size() / 3;
  Vec3 c = Vec3::Zero();
  for (long i = 0; i < p; ++i) c += x0.segment<3>(3 * i);
  c /= double(std::max<long>(1, p));
  double r2 = 0;
  for (long i = 0; i < p; ++i) r2 += (x0.segment<3>(3 * i) - c).squaredNorm();
  r2 = std::max(1e-6, r2 / double(std::max<long>(1, p)));
  const double two_sigma2 = 2 * 0.25 * r2;
  Eigen::MatrixXd k(p, p);
  for (long i = 0; i < p; ++i)
    for (long j = 0; j < p; ++j) {
      const Vec3 a = x0.segment<3>(3 * i) - c, b = x0.segment<3>(3 * j) - c;
      k(i, j) = 1 + a.dot(b) / r2 + std::exp(-(a - b).squaredNorm() / two_sigma2);
    }
  return k;
}

}  // namespace

ProjectionMetric::ProjectionMetric(const Controls& controls, const VecX& x0, bool planar, bool smooth) {
  const int p = int(x0.size() / 3);
  if (!smooth || controls.basis() != ControlBasis::kPerParticle || p == 0) return;
  // A per-particle block holds p · components variables, particle-major (control_basis.h).
  components_ = planar ? 2 : 3;
  block_ = p * components_;
  if (controls.size() % block_ != 0) return;
  kernel_ = smooth_kernel(x0);
}

Eigen::MatrixXd ProjectionMetric::times_kernel(const Eigen::MatrixXd& j) const {
  if (!smooth()) return j;
  const long p = kernel_.rows(), nc = components_;
  Eigen::MatrixXd out(j.rows(), j.cols());
  Eigen::MatrixXd axis(j.rows(), p);
  for (long b = 0; b + block_ <= j.cols(); b += block_)
    for (long c = 0; c < nc; ++c) {
      for (long i = 0; i < p; ++i) axis.col(i) = j.col(b + nc * i + c);
      const Eigen::MatrixXd smoothed = axis * kernel_;
      for (long i = 0; i < p; ++i) out.col(b + nc * i + c) = smoothed.col(i);
    }
  return out;
}

}  // namespace kf

#include "sim/cloth/filtered_pcg.h"

#include <Eigen/LU>
#include <cmath>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace kf {

void FilteredPcg::resize(int p) {
  inv_diag_.assign(p, Mat3::Identity());
  r_.setZero(3 * p);
  z_.setZero(3 * p);
  p_.setZero(3 * p);
  q_.setZero(3 * p);
}

void FilteredPcg::prepare(const BlockSparse3& A, const std::vector<char>& free) {
  tbb::parallel_for(tbb::blocked_range<int>(0, A.block_rows(), 512), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i)
      inv_diag_[i] = free[i] ? Mat3(A.block(A.diag_slot(i)).inverse()) : Mat3::Zero();
  });
}

void FilteredPcg::filter(const std::vector<char>& free, VecX& y) const {
  for (int i = 0; i < int(free.size()); ++i)
    if (!free[i]) seg(y, i).setZero();
}

void FilteredPcg::precondition(const std::vector<char>& free, const VecX& r, VecX& z) const {
  for (int i = 0; i < int(free.size()); ++i) seg(z, i).noalias() = inv_diag_[i] * seg(r, i);
}

PcgResult FilteredPcg::solve(const BlockSparse3& A, const std::vector<char>& free, const VecX& b, VecX& x,
                             double tol, int max_iterations, bool warm) {
  PcgResult res;
  if (!warm)
    for (int i = 0; i < int(free.size()); ++i)
      if (free[i]) seg(x, i).setZero();
  A.multiply(x, q_);
  r_ = b - q_;
  filter(free, r_);
  z_ = b;
  filter(free, z_);
  const double b_norm = z_.norm();
  double r_norm = r_.norm();
  const double target = tol * (b_norm > 0 ? b_norm : 1.0);
  if (r_norm <= target) {
    res.converged = true;
    res.relative_residual = b_norm > 0 ? r_norm / b_norm : r_norm;
    return res;
  }
  precondition(free, r_, z_);
  p_ = z_;
  double rz = r_.dot(z_);
  for (int it = 1; it <= max_iterations; ++it) {
    A.multiply(p_, q_);
    filter(free, q_);
    const double pq = p_.dot(q_);
    if (!(pq > 0) || !std::isfinite(pq)) break;  // not positive definite on the free set
    const double alpha = rz / pq;
    x.noalias() += alpha * p_;
    r_.noalias() -= alpha * q_;
    r_norm = r_.norm();
    res.iterations = it;
    if (r_norm <= target) {
      res.converged = true;
      break;
    }
    precondition(free, r_, z_);
    const double rz_new = r_.dot(z_);
    p_ = z_ + (rz_new / rz) * p_;
    rz = rz_new;
  }
  res.relative_residual = b_norm > 0 ? r_norm / b_norm : r_norm;
  return res;
}

}  // namespace kf

#include "sim/cloth/filtered_pcg.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace kf {

void FilteredPcg::resize(int p, Preconditioner kind, int nx, int ny) {
  kind_ = kind;
  nx_ = nx;
  ny_ = ny;
  mg_ready_ = false;
  if (kind == Preconditioner::kMultigrid && nx * ny != p) kind_ = Preconditioner::kIncompleteCholesky;
  inv_diag_.assign(p, Mat3::Identity());
  r_.setZero(3 * p);
  z_.setZero(3 * p);
  p_.setZero(3 * p);
  q_.setZero(3 * p);
}

void FilteredPcg::prepare(const BlockSparse3& A, const std::vector<char>& free) {
  ic_ok_ = mg_ok_ = false;
  if (kind_ == Preconditioner::kMultigrid) {
    if (!mg_ready_) {  // the pattern and the pins are the sheet's: the hierarchy is built once
      mg_.setup(nx_, ny_, A, free);
      mg_ready_ = true;
    }
    mg_ok_ = mg_.prepare(A);
    if (mg_ok_) return;
  }
  if (kind_ == Preconditioner::kIncompleteCholesky) {
    if (int(lower_.size()) != A.nonzero_blocks()) lower_.assign(A.nonzero_blocks(), Mat3::Zero());
    ic_ok_ = factor_ic(A, free);
    if (ic_ok_) return;
  }
  prepare_block_jacobi(A, free);
}

void FilteredPcg::prepare_block_jacobi(const BlockSparse3& A, const std::vector<char>& free) {
  tbb::parallel_for(tbb::blocked_range<int>(0, A.block_rows(), 512), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i)
      inv_diag_[i] = free[i] ? Mat3(A.block(A.diag_slot(i)).inverse()) : Mat3::Zero();
  });
}

// Left-looking IC(0) by block rows: L_ij = (A_ij - sum_{m<j} L_im L_jm^T) L_jj^-T on A's pattern, then
// L_ii = chol(A_ii - sum_{m<i} L_im L_im^T). Pinned rows and columns are left out (the filtered system).
bool FilteredPcg::factor_ic(const BlockSparse3& A, const std::vector<char>& free) {
  const int n = A.block_rows();
  for (int i = 0; i < n; ++i) {
    if (!free[i]) {
      inv_diag_[i].setZero();
      continue;
    }
    const int d = A.diag_slot(i);
    Mat3 diag = A.block(d);
    for (int k = A.row_start(i); k < d; ++k) {
      const int j = A.col(k);
      if (!free[j]) {
        lower_[k].setZero();
        continue;
      }
      Mat3 s = A.block(k);
      // Columns m < j present in both row i and row j (both lists sorted).
      int a = A.row_start(i), b = A.row_start(j);
      const int b_end = A.diag_slot(j);
      while (a < k && b < b_end) {
        const int ca = A.col(a), cb = A.col(b);
        if (ca < cb) ++a;
        else if (cb < ca) ++b;
        else {
          if (free[ca]) s.noalias() -= lower_[a] * lower_[b].transpose();
          ++a;
          ++b;
        }
      }
      lower_[k].noalias() = s * inv_diag_[j].transpose();
      diag.noalias() -= lower_[k] * lower_[k].transpose();
    }
    Eigen::LLT<Mat3> llt(diag);
    if (llt.info() != Eigen::Success) return false;
    const Mat3 l = llt.matrixL();
    if (!(l.diagonal().minCoeff() > 1e-12 * std::sqrt(A.block(d).diagonal().maxCoeff()))) return false;
    inv_diag_[i] = l.inverse();
  }
  return true;
}

void FilteredPcg::filter(const std::vector<char>& free, VecX& y) const {
  for (int i = 0; i < int(free.size()); ++i)
    if (!free[i]) seg(y, i).setZero();
}

void FilteredPcg::precondition(const BlockSparse3& A, const std::vector<char>& free, const VecX& r,
                               VecX& z) {
  const int n = int(free.size());
  if (mg_ok_) {
    mg_.apply(A, r, z);
    return;
  }
  if (!ic_ok_) {
    for (int i = 0; i < n; ++i) seg(z, i).noalias() = inv_diag_[i] * seg(r, i);
    return;
  }
  // z = L^-T L^-1 r: forward substitution by rows, then backward by columns of L^T.
  for (int i = 0; i < n; ++i) {
    if (!free[i]) {
      seg(z, i).setZero();
      continue;
    }
    Vec3 y = seg(r, i);
    for (int k = A.row_start(i); k < A.diag_slot(i); ++k)
      if (free[A.col(k)]) y.noalias() -= lower_[k] * seg(z, A.col(k));
    seg(z, i).noalias() = inv_diag_[i] * y;
  }
  for (int i = n - 1; i >= 0; --i) {
    if (!free[i]) continue;
    const Vec3 zi = inv_diag_[i].transpose() * seg(z, i);
    seg(z, i) = zi;
    for (int k = A.row_start(i); k < A.diag_slot(i); ++k)
      if (free[A.col(k)]) seg(z, A.col(k)).noalias() -= lower_[k].transpose() * zi;
  }
}

PcgResult FilteredPcg::solve(const BlockSparse3& A, const std::vector<char>& free, const VecX& b, VecX& x,
                             double tol, int max_iterations, bool warm) {
  PcgResult res = solve_once(A, free, b, x, tol, max_iterations, warm);
  if (res.converged || !mg_ok_) return res;
  // A V-cycle that stopped being positive definite (a coarse level's smoother diverging) breaks CG; the
  // step is solved again, from zero, with block Jacobi (deterministic: it depends on this step alone).
  mg_ok_ = false;
  prepare_block_jacobi(A, free);
  const int spent = res.iterations;
  res = solve_once(A, free, b, x, tol, max_iterations, false);
  res.iterations += spent;
  return res;
}

PcgResult FilteredPcg::solve_once(const BlockSparse3& A, const std::vector<char>& free, const VecX& b, VecX& x,
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
  precondition(A, free, r_, z_);
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
    precondition(A, free, r_, z_);
    const double rz_new = r_.dot(z_);
    if (!(rz_new > 0)) break;  // the preconditioner is not positive definite here
    p_ = z_ + (rz_new / rz) * p_;
    rz = rz_new;
  }
  res.relative_residual = b_norm > 0 ? r_norm / b_norm : r_norm;
  return res;
}

}  // namespace kf

#include "sim/cloth/filtered_pcg.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

namespace kf {

namespace {
// Vector operations run over fixed chunks of particles, in parallel when there are several, and sums add
// each chunk's partial sum in chunk order: the same bits on any thread count. Below kParallelFrom
// particles the whole vector is one chunk (a parallel loop costs more than it saves there), so small sheets
// keep the rounding of whole-vector sums.
constexpr int kChunk = 256;
constexpr int kParallelFrom = 1024;

int chunk_size(int n) { return n < kParallelFrom ? std::max(n, 1) : kChunk; }

// f(begin, end, chunk) over [0, n).
template <class F>
void for_chunks(int n, F&& f) {
  const int size = chunk_size(n), chunks = (n + size - 1) / size;
  if (chunks <= 1) {
    f(0, n, 0);
    return;
  }
  tbb::parallel_for(
      tbb::blocked_range<int>(0, chunks, 1),
      [&](const tbb::blocked_range<int>& r) {
        for (int c = r.begin(); c < r.end(); ++c) f(c * size, std::min(n, (c + 1) * size), c);
      },
      tbb::static_partitioner());
}

// The entries of particles [begin, end).
auto span(VecX& v, int begin, int end) { return v.segment(3 * begin, 3 * (end - begin)); }
auto span(const VecX& v, int begin, int end) { return v.segment(3 * begin, 3 * (end - begin)); }
}  // namespace

void FilteredPcg::resize(int p, Preconditioner kind, int nx, int ny) {
  kind_ = kind;
  nx_ = nx;
  ny_ = ny;
  mg_ready_ = false;
  ic_ = IncompleteCholesky();  // analysed again at the first prepare
  ic_keep_.clear();
  if (kind == Preconditioner::kMultigrid && nx * ny != p) kind_ = Preconditioner::kIncompleteCholesky;
  inv_diag_.assign(p, Mat3::Identity());
  r_.setZero(3 * p);
  z_.setZero(3 * p);
  p_.setZero(3 * p);
  q_.setZero(3 * p);
  partial_.assign((p + chunk_size(p) - 1) / chunk_size(p), 0.0);
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
    if (!ic_.analysed_for(A)) ic_.analyse(A, ic_keep_);  // the pattern is the sheet's: its order is made once
    ic_ok_ = ic_.factor(A, free);
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

double FilteredPcg::sum_partials(int n) const {
  double sum = 0;
  const int size = chunk_size(n);
  for (int c = 0; c < (n + size - 1) / size; ++c) sum += partial_[c];
  return sum;
}

double FilteredPcg::chunked_dot(const VecX& a, const VecX& b) {
  const int n = int(a.size()) / 3;
  for_chunks(n, [&](int begin, int end, int c) { partial_[c] = span(a, begin, end).dot(span(b, begin, end)); });
  return sum_partials(n);
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
    for_chunks(n, [&](int begin, int end, int) {
      for (int i = begin; i < end; ++i) seg(z, i).noalias() = inv_diag_[i] * seg(r, i);
    });
    return;
  }
  ic_.apply(free, r, z);
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
  double rz = chunked_dot(r_, z_);
  const int n = int(free.size());
  double* part = partial_.data();
  for (int it = 1; it <= max_iterations; ++it) {
    for_chunks(n, [&](int begin, int end, int c) {  // q = S A p, and p . q
      for (int i = begin; i < end; ++i) seg(q_, i) = free[i] ? A.row_times(i, p_) : Vec3::Zero();
      part[c] = span(p_, begin, end).dot(span(q_, begin, end));
    });
    const double pq = sum_partials(n);
    if (!(pq > 0) || !std::isfinite(pq)) break;  // not positive definite on the free set
    const double alpha = rz / pq;
    for_chunks(n, [&](int begin, int end, int c) {  // x += alpha p, r -= alpha q, and r . r
      span(x, begin, end) += alpha * span(p_, begin, end);
      span(r_, begin, end) -= alpha * span(q_, begin, end);
      part[c] = span(r_, begin, end).squaredNorm();
    });
    r_norm = std::sqrt(sum_partials(n));
    res.iterations = it;
    if (r_norm <= target) {
      res.converged = true;
      break;
    }
    precondition(A, free, r_, z_);
    const double rz_new = chunked_dot(r_, z_);
    if (!(rz_new > 0)) break;  // the preconditioner is not positive definite here
    const double beta = rz_new / rz;
    for_chunks(n, [&](int begin, int end, int) { span(p_, begin, end) = span(z_, begin, end) + beta * span(p_, begin, end); });
    rz = rz_new;
  }
  res.relative_residual = b_norm > 0 ? r_norm / b_norm : r_norm;
  return res;
}

}  // namespace kf

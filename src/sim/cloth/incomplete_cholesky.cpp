#include "sim/cloth/incomplete_cholesky.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

namespace kf {

namespace {
// Below this many particles one thread does the whole factor: a split saves less than it costs.
constexpr int kSplitFrom = 512;

// The particles at or after `mid` with a kept neighbour before it.
std::vector<int> separator_after(const BlockSparse3& A, const std::vector<char>& keep, int mid) {
  std::vector<int> s;
  for (int i = mid; i < A.block_rows(); ++i)
    for (int k = A.row_start(i); k < A.row_start(i + 1); ++k)
      if (A.col(k) < mid && (keep.empty() || keep[k])) {
        s.push_back(i);
        break;
      }
  return s;
}
}  // namespace

// f(half, begin, end) for the two halves' positions, at once. The static partition keeps each half on the
// same thread every time (when there are two), so its rows stay in that core's cache.
template <class F>
void IncompleteCholesky::halves(F&& f) const {
  tbb::parallel_for(
      tbb::blocked_range<int>(0, 2, 1),
      [&](const tbb::blocked_range<int>& r) {
        for (int h = r.begin(); h < r.end(); ++h) f(h, h == 0 ? 0 : end_[0], end_[h]);
      },
      tbb::static_partitioner());
}

void IncompleteCholesky::analyse(const BlockSparse3& A, const std::vector<char>& keep) {
  const int n = A.block_rows();
  a_blocks_ = A.nonzero_blocks();
  order_.clear();
  std::vector<char> in_separator(n, 0);
  int mid = n;
  if (n >= kSplitFrom) {
    // Balance the halves: the separator comes out of the second one.
    const int width = int(separator_after(A, keep, n / 2).size());
    mid = (n - width) / 2;
    const std::vector<int> s = separator_after(A, keep, mid);
    if (int(s.size()) <= n / 8)
      for (int i : s) in_separator[i] = 1;
    else
      mid = n;  // no narrow separator in this numbering: one half
  }
  for (int i = 0; i < mid; ++i) order_.push_back(i);
  end_[0] = mid;
  for (int i = n - 1; i >= mid; --i)
    if (!in_separator[i]) order_.push_back(i);
  end_[1] = int(order_.size());
  for (int i = mid; i < n; ++i)
    if (in_separator[i]) order_.push_back(i);
  position_.assign(n, 0);
  for (int q = 0; q < n; ++q) position_[order_[q]] = q;

  start_.assign(1, 0);
  col_pos_.clear();
  col_.clear();
  a_slot_.clear();
  std::vector<std::pair<int, int>> row;  // (column position, slot in A)
  for (int q = 0; q < n; ++q) {
    const int i = order_[q];
    row.clear();
    for (int k = A.row_start(i); k < A.row_start(i + 1); ++k)
      if (position_[A.col(k)] < q && (keep.empty() || keep[k])) row.emplace_back(position_[A.col(k)], k);
    std::sort(row.begin(), row.end());
    for (const auto& [c, k] : row) {
      col_pos_.push_back(c);
      col_.push_back(order_[c]);
      a_slot_.push_back(k);
    }
    start_.push_back(int(col_pos_.size()));
  }
  lower_.assign(col_pos_.size(), Mat3::Zero());
  inv_diag_.assign(n, Mat3::Zero());
}

// Left-looking by rows: L_ij = (A_ij - sum_{m<j} L_im L_jm^T) L_jj^-T on A's pattern, then
// L_ii = chol(A_ii - sum_{m<i} L_im L_im^T), "<" in elimination order.
bool IncompleteCholesky::factor_rows(const BlockSparse3& A, const std::vector<char>& free, int begin, int end) {
  for (int q = begin; q < end; ++q) {
    const int i = order_[q];
    if (!free[i]) {
      inv_diag_[i].setZero();
      continue;
    }
    const int d = A.diag_slot(i);
    Mat3 diag = A.block(d);
    for (int k = start_[q]; k < start_[q + 1]; ++k) {
      const int j = col_[k];
      if (!free[j]) {
        lower_[k].setZero();
        continue;
      }
      Mat3 s = A.block(a_slot_[k]);
      // Columns before j present in both row q and row j's position (both lists sorted).
      int a = start_[q], b = start_[col_pos_[k]];
      const int b_end = start_[col_pos_[k] + 1];
      while (a < k && b < b_end) {
        const int ca = col_pos_[a], cb = col_pos_[b];
        if (ca < cb) ++a;
        else if (cb < ca) ++b;
        else {
          if (free[col_[a]]) s.noalias() -= lower_[a] * lower_[b].transpose();
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

bool IncompleteCholesky::factor(const BlockSparse3& A, const std::vector<char>& free) {
  if (end_[0] == end_[1]) return factor_rows(A, free, 0, int(order_.size()));
  bool ok[2] = {true, true};
  halves([&](int h, int begin, int end) { ok[h] = factor_rows(A, free, begin, end); });
  return ok[0] && ok[1] && factor_rows(A, free, end_[1], int(order_.size()));
}

// L y = r by rows, in elimination order. Entries in pinned columns are zero in the factor (and z is zero on
// pinned rows), so no row asks which of its columns are free.
void IncompleteCholesky::forward_rows(const std::vector<char>& free, const VecX& r, VecX& z, int begin,
                                      int end) const {
  for (int q = begin; q < end; ++q) {
    const int i = order_[q];
    if (!free[i]) {
      seg(z, i).setZero();
      continue;
    }
    Vec3 y = seg(r, i);
    for (int k = start_[q]; k < start_[q + 1]; ++k) y.noalias() -= lower_[k] * seg(z, col_[k]);
    seg(z, i).noalias() = inv_diag_[i] * y;
  }
}

// L^T z = y by columns, in reverse elimination order: each row pushes its part into earlier rows.
void IncompleteCholesky::backward_rows(const std::vector<char>& free, VecX& z, int begin, int end) const {
  for (int q = end - 1; q >= begin; --q) {
    const int i = order_[q];
    if (!free[i]) continue;
    const Vec3 zi = inv_diag_[i].transpose() * seg(z, i);
    seg(z, i) = zi;
    for (int k = start_[q]; k < start_[q + 1]; ++k) seg(z, col_[k]).noalias() -= lower_[k].transpose() * zi;
  }
}

void IncompleteCholesky::apply(const std::vector<char>& free, const VecX& r, VecX& z) const {
  const int n = int(order_.size());
  if (end_[0] == end_[1]) {
    forward_rows(free, r, z, 0, n);
    backward_rows(free, z, 0, n);
    return;
  }
  halves([&](int, int begin, int end) { forward_rows(free, r, z, begin, end); });
  forward_rows(free, r, z, end_[1], n);
  backward_rows(free, z, end_[1], n);
  halves([&](int, int begin, int end) { backward_rows(free, z, begin, end); });
}

}  // namespace kf

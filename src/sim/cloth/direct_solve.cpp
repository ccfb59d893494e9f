#include "sim/cloth/direct_solve.h"

namespace kf {

bool FilteredDirect::factor(const BlockSparse3& A, const std::vector<char>& free) {
  const int p = A.block_rows();
  if (int(index_.size()) != p) {
    index_.assign(p, -1);
    int nf = 0;
    for (int i = 0; i < p; ++i)
      if (free[i]) index_[i] = nf++;
    matrix_.resize(3 * nf, 3 * nf);
    rhs_.resize(3 * nf);
    sol_.resize(3 * nf);
    analysed_ = false;
  }
  triplets_.clear();
  for (int i = 0; i < p; ++i) {
    if (index_[i] < 0) continue;
    for (int k = A.row_start(i); k < A.row_start(i + 1); ++k) {
      const int j = A.col(k);
      if (index_[j] < 0) continue;
      const Mat3& b = A.block(k);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) triplets_.emplace_back(3 * index_[i] + r, 3 * index_[j] + c, b(r, c));
    }
  }
  matrix_.setFromTriplets(triplets_.begin(), triplets_.end());
  if (!analysed_) {
    ldlt_.analyzePattern(matrix_);
    analysed_ = true;
  }
  ldlt_.factorize(matrix_);
  ok_ = ldlt_.info() == Eigen::Success;
  return ok_;
}

bool FilteredDirect::solve(const BlockSparse3& A, const std::vector<char>& free, const VecX& b, VecX& x) {
  if (!ok_) return false;
  const int p = A.block_rows();
  for (int i = 0; i < p; ++i) {
    if (index_[i] < 0) continue;
    Vec3 r = seg(b, i);
    for (int k = A.row_start(i); k < A.row_start(i + 1); ++k)
      if (!free[A.col(k)]) r -= A.block(k) * seg(x, A.col(k));
    rhs_.segment<3>(3 * index_[i]) = r;
  }
  sol_ = ldlt_.solve(rhs_);
  if (ldlt_.info() != Eigen::Success || !sol_.allFinite()) return false;
  for (int i = 0; i < p; ++i)
    if (index_[i] >= 0) seg(x, i) = sol_.segment<3>(3 * index_[i]);
  return true;
}

}  // namespace kf

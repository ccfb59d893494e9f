#include "sim/cloth/direct_solve.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace kf {

const char* FilteredDirect::backend() {
#ifdef KEYFRAME_CHOLMOD
  return "CHOLMOD supernodal LL^T";
#else
  return "Eigen simplicial LDL^T";
#endif
}

// The lower triangle of A_FF: entry (3 fi + r, 3 fj + c) with fi >= fj. Each entry's value is tagged with
// where it comes from in A, then read back in the compressed order the solver sees.
void FilteredDirect::build_pattern(const BlockSparse3& A, const std::vector<char>& free) {
  const int p = A.block_rows();
  index_.assign(p, -1);
  int nf = 0;
  for (int i = 0; i < p; ++i)
    if (free[i]) index_[i] = nf++;
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < p; ++i) {
    if (index_[i] < 0) continue;
    for (int k = A.row_start(i); k <= A.diag_slot(i); ++k) {
      const int j = A.col(k);
      if (index_[j] < 0) continue;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          if (j < i || c <= r) t.emplace_back(3 * index_[i] + r, 3 * index_[j] + c, double(k * 9 + r * 3 + c));
    }
  }
  matrix_.resize(3 * nf, 3 * nf);
  matrix_.setFromTriplets(t.begin(), t.end());
  matrix_.makeCompressed();
  source_.resize(matrix_.nonZeros());
  for (int e = 0; e < int(source_.size()); ++e) source_[e] = int(matrix_.valuePtr()[e]);
  rhs_.resize(3 * nf);
  sol_.resize(3 * nf);
  analysed_ = false;
}

bool FilteredDirect::factor(const BlockSparse3& A, const std::vector<char>& free) {
  if (int(index_.size()) != A.block_rows()) build_pattern(A, free);
  double* values = matrix_.valuePtr();
  const int nnz = int(source_.size());
  // Each entry is written by one task: the matrix does not depend on the thread count.
  tbb::parallel_for(tbb::blocked_range<int>(0, nnz, 4096), [&](const tbb::blocked_range<int>& r) {
    for (int e = r.begin(); e < r.end(); ++e) {
      const int s = source_[e];
      values[e] = A.block(s / 9)((s % 9) / 3, s % 3);
    }
  });
  if (!analysed_) {
    factor_.analyzePattern(matrix_);
    analysed_ = true;
  }
  factor_.factorize(matrix_);
  ok_ = factor_.info() == Eigen::Success;
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
  sol_ = factor_.solve(rhs_);
  if (factor_.info() != Eigen::Success || !sol_.allFinite()) return false;
  for (int i = 0; i < p; ++i)
    if (index_[i] >= 0) seg(x, i) = sol_.segment<3>(3 * index_[i]);
  return true;
}

}  // namespace kf

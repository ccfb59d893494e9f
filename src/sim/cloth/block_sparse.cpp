#include "sim/cloth/block_sparse.h"

#include <algorithm>
#include <stdexcept>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include "core/check.h"

namespace kf {

void BlockSparse3::set_pattern(const std::vector<std::vector<int>>& cols) {
  const int n = int(cols.size());
  row_start_.assign(1, 0);
  col_.clear();
  diag_.assign(n, -1);
  for (int i = 0; i < n; ++i) {
    std::vector<int> c = cols[i];
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
    for (int j : c) {
      if (j == i) diag_[i] = int(col_.size());
      col_.push_back(j);
    }
    CHECK_GE(diag_[i], 0);  // every row holds its diagonal block
    row_start_.push_back(int(col_.size()));
  }
  val_.assign(col_.size(), Mat3::Zero());
}

int BlockSparse3::find(int i, int j) const {
  auto b = col_.begin() + row_start_[i], e = col_.begin() + row_start_[i + 1];
  auto it = std::lower_bound(b, e, j);
  return (it != e && *it == j) ? int(it - col_.begin()) : -1;
}

void BlockSparse3::multiply(const VecX& x, VecX& y) const {
  constexpr int kGrain = 256;
  if (block_rows() <= kGrain) {  // a task costs more than a small product
    for (int i = 0; i < block_rows(); ++i) seg(y, i) = row_times(i, x);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, block_rows(), kGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) seg(y, i) = row_times(i, x);
  }, tbb::static_partitioner());
}

SpMat BlockSparse3::to_sparse() const {
  std::vector<Triplet> t;
  for (int i = 0; i < block_rows(); ++i)
    for (int k = row_start_[i]; k < row_start_[i + 1]; ++k)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) t.emplace_back(3 * i + a, 3 * col_[k] + b, val_[k](a, b));
  SpMat m(3 * block_rows(), 3 * block_rows());
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

BlockSparse3 BlockSparse3::from_sparse(const SpMat& m) {
  std::vector<std::vector<int>> cols(m.rows() / 3);
  for (int k = 0; k < m.outerSize(); ++k)
    for (SpMat::InnerIterator it(m, k); it; ++it) cols[it.row() / 3].push_back(int(it.col() / 3));
  BlockSparse3 b;
  b.set_pattern(cols);
  for (int k = 0; k < m.outerSize(); ++k)
    for (SpMat::InnerIterator it(m, k); it; ++it)
      b.block(b.find(int(it.row() / 3), int(it.col() / 3)))(it.row() % 3, it.col() % 3) = it.value();
  return b;
}

}  // namespace kf

#pragma once
// A sparse matrix of 3x3 blocks with a fixed pattern (one block row per particle).
//
// The pattern is set once; each step only overwrites block values, so nothing is allocated in the hot
// loop. Products run in parallel over block rows: each thread writes only its own rows, so the result is
// bit-identical for any thread count.
#include <vector>

#include "core/types.h"

namespace kf {

class BlockSparse3 {
 public:
  // cols[i]: the block columns present in block row i (must contain i). Blocks start at zero.
  void set_pattern(const std::vector<std::vector<int>>& cols);

  int block_rows() const { return int(row_start_.size()) - 1; }
  int nonzero_blocks() const { return int(col_.size()); }
  // Slots of row i are [row_start(i), row_start(i+1)), sorted by column.
  int row_start(int i) const { return row_start_[i]; }
  int col(int slot) const { return col_[slot]; }
  int diag_slot(int i) const { return diag_[i]; }
  // Slot of block (i, j); -1 when it is not in the pattern.
  int find(int i, int j) const;
  Mat3& block(int slot) { return val_[slot]; }
  const Mat3& block(int slot) const { return val_[slot]; }

  // Row i of (this * x): x has 3 * block_rows() entries. Inline and in scalars: every solver's inner
  // loop is this product, and the compiler keeps the three sums in registers.
  Vec3 row_times(int i, const VecX& x) const {
    double y0 = 0, y1 = 0, y2 = 0;
    const double* xd = x.data();
    for (int k = row_start_[i]; k < row_start_[i + 1]; ++k) {
      const double* a = val_[k].data();  // column-major
      const double* xv = xd + 3 * col_[k];
      const double x0 = xv[0], x1 = xv[1], x2 = xv[2];
      y0 += a[0] * x0 + a[3] * x1 + a[6] * x2;
      y1 += a[1] * x0 + a[4] * x1 + a[7] * x2;
      y2 += a[2] * x0 + a[5] * x1 + a[8] * x2;
    }
    return Vec3(y0, y1, y2);
  }
  // y = this * x (both 3 * block_rows()); y must already have the right size.
  void multiply(const VecX& x, VecX& y) const;
  // The matrix as an Eigen sparse matrix (tests, diagnostics; allocates).
  SpMat to_sparse() const;
  // The blocks of an Eigen sparse matrix of 3 x 3 blocks, the pattern the blocks holding its entries
  // (tests; allocates).
  static BlockSparse3 from_sparse(const SpMat& m);

 private:
  std::vector<int> row_start_{0}, col_, diag_;
  std::vector<Mat3> val_;
};

}  // namespace kf

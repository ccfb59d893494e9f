#pragma once
// Block incomplete Cholesky IC(0) of a filtered BlockSparse3 (the factor keeps A's block pattern, or the part
// of it the caller marks; pinned rows and columns are left out), in an elimination order that lets two
// threads share it. The cloth keeps its stretch and shear springs' blocks and drops the bending springs'
// (ClothSystem): on the pinned 50 x 50 sheet that costs a few more iterations and saves more instructions
// than they cost.
//
// Why the order: in the particles' own order each row of the factor and of both triangular solves waits for
// the one before, so IC(0) was the serial third of a cloth step. Here the particles are split into two
// halves and a separator, the particles of the second half that touch the first (one grid row of a sheet
// when its pattern has no bending blocks, two when it has). Eliminated as [first half, second half from its far end back,
// separator], a half's rows only ever meet rows of their own half before them, so the factor and the
// forward solve run the two halves at once and then the separator; the backward solve does the separator
// first. Both halves advance towards the separator: on the pinned 50 x 50 sheet (full pattern) PCG then
// needed 17.9 iterations a step against 17.6 in the particles' own order (19.9 with the second half in its
// own order).
// The order depends on the pattern alone and every row is computed the same way whatever runs beside it,
// so results are bit-identical on any thread count. A pattern without a small separator keeps one half.
#include <vector>

#include "core/types.h"
#include "sim/cloth/block_sparse.h"

namespace kf {

class IncompleteCholesky {
 public:
  // Builds the elimination order and the factor's pattern from A's (symmetric) pattern, or from the part of
  // it `keep` marks (one entry per block of A, symmetric; empty: all of it). The factor leaves the other
  // blocks out: an incomplete factor of A with them dropped.
  void analyse(const BlockSparse3& A, const std::vector<char>& keep = {});
  // True when analyse saw a pattern of this size.
  bool analysed_for(const BlockSparse3& A) const {
    return int(position_.size()) == A.block_rows() && a_blocks_ == A.nonzero_blocks();
  }
  // Factors A on the free set. False when a pivot is not positive definite.
  bool factor(const BlockSparse3& A, const std::vector<char>& free);
  // z = (L L^T)^-1 r on the free set, zero on the rest (r, z: 3 entries a particle).
  void apply(const std::vector<char>& free, const VecX& r, VecX& z) const;
  // Particles eliminated last, serially (0 when the pattern was not split).
  int separator_size() const { return int(order_.size()) - end_[1]; }

 private:
  // Rows at positions [begin, end) of the order, in order: false on a pivot that is not positive definite.
  bool factor_rows(const BlockSparse3& A, const std::vector<char>& free, int begin, int end);
  void forward_rows(const std::vector<char>& free, const VecX& r, VecX& z, int begin, int end) const;
  void backward_rows(const std::vector<char>& free, VecX& z, int begin, int end) const;
  template <class F>
  void halves(F&& f) const;

  int a_blocks_ = -1;
  std::vector<int> order_;        // position -> particle
  std::vector<int> position_;     // particle -> position
  int end_[2] = {0, 0};           // positions [0, end_[0]): first half; [end_[0], end_[1]): second; then the separator
  // Row at position q: its entries left of the diagonal in elimination order, [start_[q], start_[q + 1]),
  // sorted by the column's position.
  std::vector<int> start_{0};
  std::vector<int> col_pos_;      // the column's position
  std::vector<int> col_;          // the column's particle
  std::vector<int> a_slot_;       // the entry's block in A
  std::vector<Mat3> lower_;       // L at the entry
  std::vector<Mat3> inv_diag_;    // per particle: L_ii^-1 (lower triangular)
};

}  // namespace kf

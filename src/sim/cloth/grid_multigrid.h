#pragma once
// A geometric multigrid V-cycle over a cloth's particle grid, used as PCG's preconditioner.
//
// Why: the sheet's springs keep their stiffness as it is refined while each particle's mass shrinks, so the
// condition number of A = M - h D - h^2 K grows with the particle count and IC(0)-preconditioned CG needs
// ever more iterations (59 a step at 50 x 50, twice that at 100 x 100). A V-cycle removes the smooth error
// those iterations spend their time on, so the count stays nearly flat, and it is parallel where IC(0)'s
// triangular solves are serial.
//
// Levels: the grid nx x ny (particle (i, j) at index j nx + i) and coarser ones that keep every other grid
// line (and the last one), down to a few dozen nodes. Prolongation P is bilinear interpolation; pinned fine
// particles are cut out of it (Dirichlet rows), so the coarse operators are the Galerkin products
// P^T S A S P, built each step from the fine matrix through lists made once. Smoothing: damped block
// Jacobi, the same number of sweeps before and after the coarse correction, so the cycle is symmetric and
// positive definite as CG needs. The coarsest level is solved exactly (dense Cholesky).
// Every loop writes its own rows or sums in a fixed order: the result does not depend on the thread count.
#include <Eigen/Cholesky>
#include <vector>

#include "core/types.h"
#include "sim/cloth/block_sparse.h"

namespace kf {

// Rows of (index, weight) pairs in one array: row r is [start[r], start[r + 1]).
struct WeightedRows {
  std::vector<int> start{0}, index;
  std::vector<double> w;
  // From per-row lists, in their order.
  static WeightedRows from(const std::vector<std::vector<std::pair<int, double>>>& rows);
};

class GridMultigrid {
 public:
  // Builds the hierarchy for the grid and the pattern of A (fixed for the sheet). `free`: 0 on pinned
  // particles.
  void setup(int nx, int ny, const BlockSparse3& A, const std::vector<char>& free);
  // Recomputes smoothers and coarse operators from A's current values (after each assembly).
  // False when a level is not positive definite (the caller falls back to another preconditioner).
  bool prepare(const BlockSparse3& A);
  // z = B r, one V-cycle; r and z have 3 nx ny entries; z is zero on pinned particles.
  void apply(const BlockSparse3& A, const VecX& r, VecX& z);
  int levels() const { return int(levels_.size()); }

 private:
  struct Level {
    int nx = 0, ny = 0;
    BlockSparse3 A_own;               // the operator (level 0 uses the caller's A)
    std::vector<Mat3> inv_diag;       // damped block-Jacobi smoother: omega A_ii^-1 (0 on pinned rows)
    std::vector<char> active;         // rows the smoother and residual touch
    // Interpolation to this level's nodes from the next coarser level: node i takes
    // sum w coarse[index] over interp's range i.
    WeightedRows interp;
    // Restriction: coarse node c gathers sum w fine[index] over restriction's range c.
    WeightedRows restriction;
    // Galerkin product into the next level: coarse slot s sums w * block(index) over galerkin's range s.
    WeightedRows galerkin;
    VecX r, e, t;                     // residual, correction, scratch
  };
  const BlockSparse3& op(int l, const BlockSparse3& fine) const { return l == 0 ? fine : levels_[l].A_own; }
  void cycle(int l, const BlockSparse3& fine);
  void smooth(int l, const BlockSparse3& A, bool from_zero);

  std::vector<Level> levels_;
  Eigen::MatrixXd coarse_dense_;
  Eigen::LLT<Eigen::MatrixXd> coarse_llt_;
  Eigen::VectorXd coarse_rhs_;
};

}  // namespace kf

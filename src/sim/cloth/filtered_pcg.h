#pragma once
// Preconditioned conjugate gradients with the Baraff-Witkin filter: particles marked constrained keep the
// value the caller put in x, and the solve runs on the free particles only (S A x = S b).
// Preconditioner: a multigrid V-cycle over the sheet's grid (GridMultigrid), block incomplete Cholesky
// IC(0) on the free set (IncompleteCholesky), or the inverse of each free particle's 3x3
// diagonal block (block Jacobi). Multigrid and IC(0) fall back to block Jacobi for a step whose matrix
// they cannot use (a pivot that is not positive definite; for multigrid also a CG that breaks down).
// Vector operations run in parallel over fixed chunks of particles and sums add the chunks' partial sums
// in order; IC(0)'s order is fixed by the pattern: results do not depend on the thread count.
#include <vector>

#include "core/types.h"
#include "sim/cloth/block_sparse.h"
#include "sim/cloth/grid_multigrid.h"
#include "sim/cloth/incomplete_cholesky.h"

namespace kf {

struct PcgResult {
  int iterations = 0;
  bool converged = false;
  double relative_residual = 0;  // |S (b - A x)| / |S b|
};

enum class Preconditioner { kBlockJacobi, kIncompleteCholesky, kMultigrid };

class FilteredPcg {
 public:
  // Preallocates for p particles; multigrid needs the grid (p = nx ny).
  void resize(int p, Preconditioner kind = Preconditioner::kIncompleteCholesky, int nx = 0, int ny = 0);
  // The blocks of A the incomplete Cholesky factor keeps (one entry per block; empty, the default: all).
  // Call after resize, which forgets it.
  void set_factor_pattern(std::vector<char> keep) { ic_keep_ = std::move(keep); ic_ = IncompleteCholesky(); }
  // Builds the preconditioner from A (symmetric, blocks A_ji = A_ij^T) on free particles. Call after A
  // changes, before solve.
  void prepare(const BlockSparse3& A, const std::vector<char>& free);
  // True when the last prepare built an incomplete Cholesky factor (false: block Jacobi).
  bool incomplete_cholesky() const { return ic_ok_; }
  // True when the last prepare built the multigrid hierarchy's operators.
  bool multigrid() const { return mg_ok_; }
  // A: symmetric positive definite on the free set. b, x: 3p. On entry x holds the prescribed values on
  // constrained particles and, when `warm` is true, the initial guess on free ones (otherwise they start
  // at zero). Stops at |r| <= tol |S b|.
  PcgResult solve(const BlockSparse3& A, const std::vector<char>& free, const VecX& b, VecX& x, double tol,
                  int max_iterations, bool warm = false);

 private:
  PcgResult solve_once(const BlockSparse3& A, const std::vector<char>& free, const VecX& b, VecX& x, double tol,
                       int max_iterations, bool warm);
  void prepare_block_jacobi(const BlockSparse3& A, const std::vector<char>& free);
  void filter(const std::vector<char>& free, VecX& y) const;
  void precondition(const BlockSparse3& A, const std::vector<char>& free, const VecX& r, VecX& z);
  // Sums in fixed chunks of particles (see for_chunks): the same bits on any thread count.
  double chunked_dot(const VecX& a, const VecX& b);
  double sum_partials(int n) const;
  Preconditioner kind_ = Preconditioner::kIncompleteCholesky;
  bool ic_ok_ = false, mg_ok_ = false, mg_ready_ = false;
  int nx_ = 0, ny_ = 0;
  GridMultigrid mg_;
  IncompleteCholesky ic_;
  std::vector<char> ic_keep_;
  std::vector<Mat3> inv_diag_;  // block Jacobi: A_ii^-1
  VecX r_, z_, p_, q_;
  std::vector<double> partial_;  // one partial sum per chunk
};

}  // namespace kf

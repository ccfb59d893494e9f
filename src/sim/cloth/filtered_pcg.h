#pragma once
// Preconditioned conjugate gradients with the Baraff-Witkin filter: particles marked constrained keep the
// value the caller put in x, and the solve runs on the free particles only (S A x = S b).
// Preconditioner: the inverse of each free particle's 3x3 diagonal block (block Jacobi).
// Reductions are serial over a fixed order, so results do not depend on the thread count.
#include <vector>

#include "core/types.h"
#include "sim/cloth/block_sparse.h"

namespace kf {

struct PcgResult {
  int iterations = 0;
  bool converged = false;
  double relative_residual = 0;  // |S (b - A x)| / |S b|
};

class FilteredPcg {
 public:
  // Preallocates for p particles.
  void resize(int p);
  // Inverts the diagonal blocks of A on free particles. Call after A changes, before solve.
  void prepare(const BlockSparse3& A, const std::vector<char>& free);
  // A: symmetric positive definite on the free set. b, x: 3p. On entry x holds the prescribed values on
  // constrained particles and, when `warm` is true, the initial guess on free ones (otherwise they start
  // at zero). Stops at |r| <= tol |S b|.
  PcgResult solve(const BlockSparse3& A, const std::vector<char>& free, const VecX& b, VecX& x, double tol,
                  int max_iterations, bool warm = false);

 private:
  void filter(const std::vector<char>& free, VecX& y) const;
  void precondition(const std::vector<char>& free, const VecX& r, VecX& z) const;
  std::vector<Mat3> inv_diag_;
  VecX r_, z_, p_, q_;
};

}  // namespace kf

#pragma once
// A sparse direct solve of the cloth step's system on the free particles, the alternative to filtered
// PCG: exact to round-off, so finite differences of a simulation see no solver tolerance (gradient
// checks) and the adjoint solves the transpose of the step's own linear map.
// The sparsity pattern and the fill-reducing ordering are analysed once per sheet; each step only copies
// A's values into the factor's matrix (no allocation) and refactors numerically. With SuiteSparse
// (KEYFRAME_CHOLMOD) the factor is CHOLMOD's supernodal LL^T; without it, Eigen's SimplicialLDLT.
#include <vector>

#include <Eigen/SparseCholesky>
#ifdef KEYFRAME_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

#include "core/types.h"
#include "sim/cloth/block_sparse.h"

namespace kf {

class FilteredDirect {
 public:
  // Factors A restricted to the free particles (A symmetric positive definite there). False when the
  // factorisation fails. The free set must stay the same for the life of this object.
  bool factor(const BlockSparse3& A, const std::vector<char>& free);
  // x holds the prescribed values on constrained particles; solves A_FF x_F = b_F - A_FP x_P. b, x: 3p.
  bool solve(const BlockSparse3& A, const std::vector<char>& free, const VecX& b, VecX& x);
  // "CHOLMOD supernodal LL^T" or "Eigen simplicial LDL^T".
  static const char* backend();

 private:
  void build_pattern(const BlockSparse3& A, const std::vector<char>& free);
  std::vector<int> index_;   // position of each particle among the free ones, -1 when constrained
  // Per stored entry of matrix_ (lower triangle, compressed column order): A's block slot and the entry
  // (row, col) inside that block, as slot * 9 + row * 3 + col.
  std::vector<int> source_;
  SpMat matrix_;
#ifdef KEYFRAME_CHOLMOD
  Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower> factor_;
#else
  Eigen::SimplicialLDLT<SpMat, Eigen::Lower> factor_;
#endif
  VecX rhs_, sol_;
  bool analysed_ = false, ok_ = false;
};

}  // namespace kf

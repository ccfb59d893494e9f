#pragma once
// A sparse direct solve of the cloth step's system on the free particles (Eigen's SimplicialLDLT), the
// alternative to filtered PCG: exact to round-off, so finite differences of a simulation see no solver
// tolerance (gradient checks), at the cost of a factorisation per step. The pattern is analysed once.
#include <vector>

#include <Eigen/SparseCholesky>

#include "core/types.h"
#include "sim/cloth/block_sparse.h"

namespace kf {

class FilteredDirect {
 public:
  // Factors A restricted to the free particles (A symmetric positive definite there). False when the
  // factorisation fails.
  bool factor(const BlockSparse3& A, const std::vector<char>& free);
  // x holds the prescribed values on constrained particles; solves A_FF x_F = b_F - A_FP x_P. b, x: 3p.
  bool solve(const BlockSparse3& A, const std::vector<char>& free, const VecX& b, VecX& x);

 private:
  std::vector<int> index_;  // position of each particle among the free ones, -1 when constrained
  std::vector<Eigen::Triplet<double>> triplets_;
  SpMat matrix_;
  Eigen::SimplicialLDLT<SpMat> ldlt_;
  VecX rhs_, sol_;
  bool analysed_ = false, ok_ = false;
};

}  // namespace kf

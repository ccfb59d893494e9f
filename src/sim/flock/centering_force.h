#pragma once
// Flock centering: each agent is pulled toward the weighted mean position of its neighbourhood.
//
// With w_ij = (1 - |x_i - x_j|^2/R^2)^2 the mean counts the agent itself with weight 1:
//   m_i = (x_i + sum_j w_ij x_j) / (1 + sum_j w_ij),   f_i = c (m_i - x_i) = c a_i / b_i,
//   a_i = sum_j w_ij (x_j - x_i),   b_i = 1 + sum_j w_ij.
// The self weight keeps f smooth when the last neighbour leaves (a plain neighbour mean jumps there).
// The force is not a pair force: d f_i / d x_j depends on agent i's whole neighbourhood, K is not
// symmetric, and the adjoint applies the true transpose.
#include <vector>

#include "sim/flock/flock_force.h"

namespace kf {

struct CenteringParams {
  double strength;  // c, N/m
  double radius;    // R, m
};

class CenteringForce final : public FlockForce {
 public:
  explicit CenteringForce(CenteringParams p) : p_(p) {}
  const char* name() const override { return "centering"; }
  double radius() const override { return p_.radius; }
  void prepare(const FlockState& s) override;
  void add_force(const FlockState& s, int i, Vec3& f) const override;
  void add_KT(const FlockState& s, const VecX& y, int j, Vec3& out) const override;

 private:
  // d f_i / d x_j (j a neighbour of i) applied transposed to y3: (c/b_i)[w y3 + g ((d + m_i) . y3)].
  Vec3 block_T_times(const FlockState& s, int i, int j, const Vec3& y3) const;

  CenteringParams p_;
  VecX offset_;               // m_i - x_i = a_i / b_i per agent (3p, m), from prepare()
  std::vector<double> b_;     // b_i per agent
};

}  // namespace kf

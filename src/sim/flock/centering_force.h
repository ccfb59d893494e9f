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
#include "sim/flock/smooth_kernel.h"

namespace kf {

struct CenteringParams {
  double strength;  // c, N/m
  double radius;    // R, m
};

// One pair of agents as the neighbour loop sums it: the fused pass over all three neighbour terms
// (NeighborForces) and CenteringForce below both sum these.
struct CenteringPair {
  explicit CenteringPair(const CenteringParams& p)
      : strength(p.strength), r2_max(p.strength == 0 ? 0.0 : p.radius * p.radius), inv_r2(1.0 / (p.radius * p.radius)) {}

  // d = x_i - x_j, r2 = |d|^2 (m^2): adds the pair's w_ij to b_i and w_ij (x_j - x_i) to a_i.
  void add_sums(const Vec3& d, double r2, Vec3& a, double& b) const {
    if (!(r2 < r2_max)) return;
    const KernelWeight k = smooth_kernel_inv(r2, inv_r2);
    a -= k.w * d;
    b += k.w;
  }
  // d = x_j - x_i; y, offset (m_i - x_i) and b of both agents, cj = c / b_j: adds
  // (d f_i/d x_j)^T y_i - (d f_j/d x_i)^T y_j, the pair's share of (K^T y)_j (translation invariance gives
  // d f_j/d x_j = -sum_i d f_j/d x_i). Block (c/b_i)[w y + ((x_i - x_j) + offset_i).y g_i], g_i = -2 w' d.
  void add_KT(const Vec3& d, double r2, const Vec3& yi, const Vec3& yj, const Vec3& oi, const Vec3& oj, double bi,
              double cj, Vec3& kt) const {
    if (!(r2 < r2_max)) return;
    const KernelWeight k = smooth_kernel_inv(r2, inv_r2);
    const double w = k.w, dw = k.dw_dr2;
    const Vec3 gi = -2.0 * dw * d;
    const Vec3 from_i = (strength / bi) * (w * yi + (oi - d).dot(yi) * gi);
    const Vec3 from_j = cj * (w * yj - (d + oj).dot(yj) * gi);
    kt += from_i - from_j;
  }

  double strength;  // c, N/m
  double r2_max;    // R^2, or 0 when the term is off (strength 0)
  double inv_r2;    // 1/R^2
};

class CenteringForce final : public FlockForce {
 public:
  explicit CenteringForce(CenteringParams p) : p_(p), pair_(p) {}
  const char* name() const override { return "centering"; }
  double radius() const override { return p_.radius; }
  void prepare(const FlockState& s) override;
  void add_force(const FlockState& s, int i, Vec3& f) const override;
  void add_KT(const FlockState& s, const VecX& y, int j, Vec3& out) const override;

 private:
  CenteringParams p_;
  CenteringPair pair_;
  VecX offset_;               // m_i - x_i = a_i / b_i per agent (3p, m), from prepare()
  std::vector<double> b_;     // b_i per agent
};

}  // namespace kf

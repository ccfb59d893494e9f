#pragma once
// Velocity matching: each agent is pulled toward its neighbours' velocities (damping relative motion).
//
// Pair force on i from j, with d = x_i - x_j, w = (1 - |d|^2/R^2)^2:  f = c w (v_j - v_i).
// D is symmetric (blocks -c sum w I on the diagonal, c w I off it); K is not symmetric, because the
// weight depends on positions: d f_i / d x_i = c (v_j - v_i) (2 w' d)^T, d f_i / d x_j = its negative.
#include "sim/flock/flock_force.h"
#include "sim/flock/smooth_kernel.h"

namespace kf {

struct MatchingParams {
  double strength;  // c, N/(m/s)
  double radius;    // R, m
};

// One pair of agents as the neighbour loop sums it, per unit strength c: the fused pass over all three
// neighbour terms (NeighborForces) and MatchingForce below both sum these and scale by c once per agent.
struct MatchingPair {
  explicit MatchingPair(const MatchingParams& p)
      : r2_max(p.strength == 0 ? 0.0 : p.radius * p.radius), inv_r2(1.0 / (p.radius * p.radius)) {}

  // r2 = |x_i - x_j|^2 (m^2), velocities vi, vj (m/s): adds w (v_j - v_i), the force on i over c.
  void add_force(double r2, const Vec3& vi, const Vec3& vj, Vec3& f) const {
    if (!(r2 < r2_max)) return;
    const KernelWeight k = smooth_kernel_inv(r2, inv_r2);
    f += k.w * (vj - vi);
  }
  // d = x_j - x_i: adds this pair's share of (K^T y)_j / c, 2 w' ((v_i - v_j) . (y_j - y_i)) d, to kt and
  // of (D^T y)_j / c, w (y_i - y_j), to dt.
  void add_KT_DT(const Vec3& d, double r2, const Vec3& vi, const Vec3& vj, const Vec3& yi, const Vec3& yj, Vec3& kt,
                 Vec3& dt) const {
    if (!(r2 < r2_max)) return;
    const KernelWeight k = smooth_kernel_inv(r2, inv_r2);
    const double w = k.w, dw = k.dw_dr2;
    kt += (2.0 * dw * (vi - vj).dot(yj - yi)) * d;
    dt += w * (yi - yj);
  }

  double r2_max;  // R^2, or 0 when the term is off (strength 0)
  double inv_r2;  // 1/R^2
};

// The same pair in closed form (for checks): d = x_i - x_j (m), dv = v_j - v_i (m/s). Force on agent i
// (N); the force on j is its negative.
Vec3 matching_pair_force(const MatchingParams& p, const Vec3& d, const Vec3& dv);
// d f_i / d x_i (N/m) of one pair; d f_i / d x_j is its negative.
Mat3 matching_pair_dx(const MatchingParams& p, const Vec3& d, const Vec3& dv);
// c w (N/(m/s)): d f_i / d v_j = c w I and d f_i / d v_i = -c w I for this pair.
double matching_pair_dv(const MatchingParams& p, const Vec3& d);

class MatchingForce final : public FlockForce {
 public:
  explicit MatchingForce(MatchingParams p) : p_(p), pair_(p) {}
  const char* name() const override { return "matching"; }
  double radius() const override { return p_.radius; }
  void add_force(const FlockState& s, int i, Vec3& f) const override;
  void add_KT(const FlockState& s, const VecX& y, int j, Vec3& out) const override;
  void add_DT(const FlockState& s, const VecX& y, int j, Vec3& out) const override;

 private:
  MatchingParams p_;
  MatchingPair pair_;
  // (K^T y)_j and (D^T y)_j over c.
  void sum_KT_DT(const FlockState& s, const VecX& y, int j, Vec3& km, Vec3& dm) const;
};

}  // namespace kf

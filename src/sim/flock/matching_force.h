#pragma once
// Velocity matching: each agent is pulled toward its neighbours' velocities (damping relative motion).
//
// Pair force on i from j, with d = x_i - x_j, w = (1 - |d|^2/R^2)^2:  f = c w (v_j - v_i).
// D is symmetric (blocks -c sum w I on the diagonal, c w I off it); K is not symmetric, because the
// weight depends on positions: d f_i / d x_i = c (v_j - v_i) (2 w' d)^T, d f_i / d x_j = its negative.
#include "sim/flock/flock_force.h"

namespace kf {

struct MatchingParams {
  double strength;  // c, N/(m/s)
  double radius;    // R, m
};

// d = x_i - x_j (m), dv = v_j - v_i (m/s). Force on agent i (N); the force on j is its negative.
Vec3 matching_pair_force(const MatchingParams& p, const Vec3& d, const Vec3& dv);
// d f_i / d x_i (N/m) of one pair; d f_i / d x_j is its negative.
Mat3 matching_pair_dx(const MatchingParams& p, const Vec3& d, const Vec3& dv);
// c w (N/(m/s)): d f_i / d v_j = c w I and d f_i / d v_i = -c w I for this pair.
double matching_pair_dv(const MatchingParams& p, const Vec3& d);

class MatchingForce final : public FlockForce {
 public:
  explicit MatchingForce(MatchingParams p) : p_(p) {}
  const char* name() const override { return "matching"; }
  double radius() const override { return p_.radius; }
  void add_force(const FlockState& s, int i, Vec3& f) const override;
  void add_KT(const FlockState& s, const VecX& y, int j, Vec3& out) const override;
  void add_DT(const FlockState& s, const VecX& y, int j, Vec3& out) const override;

 private:
  MatchingParams p_;
};

}  // namespace kf

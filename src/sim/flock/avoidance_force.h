#pragma once
// Collision avoidance: agents closer than `radius` push each other apart.
//
// Pair force on i from j, with d = x_i - x_j, r = |d|:
//   f = k w(r) d / sqrt(r^2 + eps^2),   w = (1 - r^2/R^2)^3,   eps = 0.3 R.
// Far from contact it is a push of k w along the unit direction; the softened direction keeps it
// finite (and zero) when two agents coincide, and its stiffness bounded (k / eps) for the explicit step.
// Position-only, so D = 0; the pair Jacobian is symmetric and K^T = K.
#include "sim/flock/flock_force.h"

namespace kf {

struct AvoidanceParams {
  double strength;  // k, N
  double radius;    // R, m
};

// d = x_i - x_j (m). Force on agent i (N); the force on j is its negative.
Vec3 avoidance_pair_force(const AvoidanceParams& p, const Vec3& d);
// d f_i / d x_i (N/m), symmetric; d f_i / d x_j is its negative.
Mat3 avoidance_pair_jacobian(const AvoidanceParams& p, const Vec3& d);

class AvoidanceForce final : public FlockForce {
 public:
  explicit AvoidanceForce(AvoidanceParams p) : p_(p) {}
  const char* name() const override { return "avoidance"; }
  double radius() const override { return p_.radius; }
  void add_force(const FlockState& s, int i, Vec3& f) const override;
  void add_KT(const FlockState& s, const VecX& y, int j, Vec3& out) const override;

 private:
  AvoidanceParams p_;
};

}  // namespace kf

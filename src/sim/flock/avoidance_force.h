#pragma once
// Collision avoidance: agents closer than `radius` push each other apart.
//
// Pair force on i from j, with d = x_i - x_j, r = |d|:
//   f = k w(r) d / sqrt(r^2 + eps^2),   w = (1 - r^2/R^2)^3,   eps = 0.3 R.
// Far from contact it is a push of k w along the unit direction; the softened direction keeps it
// finite (and zero) when two agents coincide, and its stiffness bounded (k / eps) for the explicit step.
// Position-only, so D = 0; the pair Jacobian is symmetric and K^T = K.
#include <cmath>

#include "sim/flock/flock_force.h"
#include "sim/flock/smooth_kernel.h"

namespace kf {

struct AvoidanceParams {
  double strength;  // k, N
  double radius;    // R, m
};

// One pair of agents as the neighbour loop sums it, per unit strength k: the fused pass over all three
// neighbour terms (NeighborForces) and AvoidanceForce below both sum these and scale by k once per agent.
struct AvoidancePair {
  static constexpr double kSoftening = 0.3;  // eps / R

  explicit AvoidancePair(const AvoidanceParams& p)
      : r2_max(p.strength == 0 ? 0.0 : p.radius * p.radius),
        inv_r2(1.0 / (p.radius * p.radius)),
        eps2(kSoftening * kSoftening * (p.radius * p.radius)) {}

  // d = x_i - x_j, r2 = |d|^2 (m^2): adds w g d, the force on i over k.
  void add_force(const Vec3& d, double r2, Vec3& f) const {
    if (!(r2 < r2_max)) return;
    const KernelWeight k = smooth_kernel_inv(r2, inv_r2);
    f += (k.w / std::sqrt(r2 + eps2)) * d;
  }
  // d = x_j - x_i, e = y_j - y_i: adds J(d) e over k, J = w g I + 2 (w' g + w g') d d^T with
  // g = (r2 + eps^2)^-1/2 (symmetric, even in d), so that the sum over i is (K^T y)_j / k.
  void add_KT(const Vec3& d, double r2, const Vec3& e, Vec3& out) const {
    if (!(r2 < r2_max)) return;
    const KernelWeight k = smooth_kernel_inv(r2, inv_r2);
    const double w = k.w, dw = k.dw_dr2;
    const double g = 1.0 / std::sqrt(r2 + eps2);
    out += (w * g) * e + (2.0 * (dw * g - 0.5 * w * g * g * g) * d.dot(e)) * d;
  }

  double r2_max;  // R^2, or 0 when the term is off (strength 0): then no pair is near
  double inv_r2;  // 1/R^2
  double eps2;    // eps^2 (m^2)
};

// The same pair in closed form (for checks): d = x_i - x_j (m). Force on agent i (N); on j its negative.
Vec3 avoidance_pair_force(const AvoidanceParams& p, const Vec3& d);
// d f_i / d x_i (N/m), symmetric; d f_i / d x_j is its negative.
Mat3 avoidance_pair_jacobian(const AvoidanceParams& p, const Vec3& d);

class AvoidanceForce final : public FlockForce {
 public:
  explicit AvoidanceForce(AvoidanceParams p) : p_(p), pair_(p) {}
  const char* name() const override { return "avoidance"; }
  double radius() const override { return p_.radius; }
  void add_force(const FlockState& s, int i, Vec3& f) const override;
  void add_KT(const FlockState& s, const VecX& y, int j, Vec3& out) const override;

 private:
  AvoidanceParams p_;
  AvoidancePair pair_;
};

}  // namespace kf

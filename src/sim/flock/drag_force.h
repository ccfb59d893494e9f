#pragma once
// Drag: f_i = -c v_i. Velocity-only and diagonal: K = 0, D = -c I (symmetric).
#include "sim/flock/flock_force.h"

namespace kf {

class DragForce final : public FlockForce {
 public:
  explicit DragForce(double strength) : c_(strength) {}  // c: N/(m/s)
  const char* name() const override { return "drag"; }
  void add_force(const FlockState& s, int i, Vec3& f) const override { f -= c_ * seg(s.v, i); }
  void add_DT(const FlockState& s, const VecX& y, int j, Vec3& out) const override { out -= c_ * seg(y, j); }

 private:
  double c_;
};

}  // namespace kf

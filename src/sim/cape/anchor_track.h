#pragma once
// Pinned cape particles that follow the character's shoulders: each pinned particle sits at a fixed
// arc-length parameter along the polyline through the skinned anchor vertices, evaluated per step.
#include <vector>

#include "sim/cloth/pin_track.h"

namespace kf {

class AnchorTrack final : public PinTrack {
 public:
  // anchors[n]: the anchor points (metres, world frame, in polyline order) at step n = 0 .. N.
  // pinned: particle indices; params: their arc-length parameter in [0, 1] along the polyline at step 0.
  // particles: p (size of the lookup table). h: step length, s.
  AnchorTrack(const std::vector<std::vector<Vec3>>& anchors, const std::vector<int>& pinned,
              const std::vector<double>& params, int particles, double h);

  // Steps past N hold the last position with zero velocity; velocity is the forward difference to n+1.
  void state(int n, int particle, const Vec3& x0, Vec3& position, Vec3& velocity) const override;

  int steps() const { return int(table_.size()) - 1; }

 private:
  std::vector<std::vector<Vec3>> table_;  // [step][slot]
  std::vector<int> slot_;                 // particle -> slot, -1 if not pinned
  double h_;
};

// Positions at the given arc-length parameters (each in [0, 1]) of the polyline `points` (at least 1).
std::vector<Vec3> polyline_points(const std::vector<Vec3>& points, const std::vector<double>& params);

}  // namespace kf

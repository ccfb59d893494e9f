#pragma once
// Avoidance, velocity matching and centering evaluated together in one pass over each agent's
// neighbour list, forward and transposed: the loop sums each term's pair struct (AvoidancePair,
// MatchingPair, CenteringPair, defined beside the terms) and scales by the strengths once per agent.
// The terms' own classes sum the same structs one term at a time (tests/sim/flock_neighbor_forces_test.cpp).
//
// Forward, for agent i: the summed force and the centering quantities offset_i = m_i - x_i (m) and
// b_i = 1 + sum_j w_ij that the transposed pass needs for every neighbour.
// Transposed, for agent j: (K^T y)_j and (D^T y)_j of the three terms, given offset and b of all agents.
// A term with strength 0 is off; each term's kernel is exactly zero beyond its own radius, so the list
// may hold neighbours within any larger radius.
#include <span>
#include <vector>

#include "core/types.h"
#include "scene/flock_spec.h"
#include "sim/flock/avoidance_force.h"
#include "sim/flock/centering_force.h"
#include "sim/flock/matching_force.h"

namespace kf {

class NeighborForces {
 public:
  explicit NeighborForces(const FlockSpec& spec);

  // Largest radius of an active term (m); 0 when no term needs neighbours.
  double radius() const { return radius_; }
  bool any() const { return radius_ > 0; }

  // x, v: 3p positions (m) and velocities (m/s); nbrs: neighbours of i. Returns the force on i (N) and
  // writes offset_i (m) and b_i.
  Vec3 force(const VecX& x, const VecX& v, std::span<const int> nbrs, int i, Vec3& offset_i, double& b_i) const;

  // y: 3p; offset: 3p, b: p (from force() or centering() at this x). Adds (K^T y)_j to kt, (D^T y)_j to dt.
  void transpose_apply(const VecX& x, const VecX& v, const VecX& y, std::span<const int> nbrs, int j,
                       const VecX& offset, const std::vector<double>& b, Vec3& kt, Vec3& dt) const;

  // Only offset_i and b_i (for a transposed pass at a state whose forward pass was not recorded).
  void centering(const VecX& x, std::span<const int> nbrs, int i, Vec3& offset_i, double& b_i) const;

 private:
  double ka_, kmatch_, kc_;  // strengths
  AvoidancePair avoid_;
  MatchingPair match_;
  CenteringPair centre_;
  double radius_ = 0;
};

}  // namespace kf

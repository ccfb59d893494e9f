#pragma once
// Avoidance, velocity matching and centering evaluated together in one pass over each agent's
// neighbour list, forward and transposed: the same pair formulas as the terms' own pair structs
// (AvoidancePair, MatchingPair, CenteringPair, defined beside the terms), written out in the ground plane
// (x, z) over agent data packed into one contiguous entry per agent, so a neighbour costs one cache line
// and no work on the y components, which are zero. Strengths scale each sum once per agent. The terms'
// own classes sum the same formulas one term at a time in 3D (tests/sim/flock_neighbor_forces_test.cpp).
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
#include "sim/flock/flock_simd.h"

namespace kf {

// One agent as the forward pass reads it: position and velocity in the ground plane (m, m/s).
struct AgentMotion {
  double x, z, vx, vz;
};

// One agent as the transposed pass reads it: its motion, y (the vector K^T and D^T are applied to), its
// centering offset (m), c / b for centering strength c, and q, the weight of the derivative of its summed
// matching weights (0 unless the step takes damping implicitly: FlockSystem).
struct AgentAdjoint {
  double x, z, vx, vz, yx, yz, ox, oz, c_over_b, q;
};

// Planar vectors of the pair loops (x, z).
struct Planar {
  double x = 0, z = 0;
};

class NeighborForces {
 public:
  explicit NeighborForces(const FlockSpec& spec);

  // Largest radius of an active term (m); 0 when no term needs neighbours.
  double radius() const { return radius_; }
  bool any() const { return radius_ > 0; }
  double centering_strength() const { return kc_; }

  // a: all agents; nbrs: neighbours of i, reordered (work space). Returns the force on i (N) and writes
  // offset_i (m), b_i and damping_i = c sum_j w_ij, how strongly matching pulls i's own velocity
  // (-D_ii, N/(m/s)).
  Planar force(const AgentMotion* a, std::span<int> nbrs, int i, Planar& offset_i, double& b_i,
               double& damping_i) const;

  // a: all agents (y, offsets and c/b filled); nbrs: neighbours of j, reordered (work space). Returns
  // (K^T y)_j in kt and (D^T y)_j in dt. With `summed_weights`, kt also gets sum_i (q_i + q_j) dS_i/dx_j
  // over the agents' summed matching weights S_i = sum_k w_ik (i = j included).
  void transpose_apply(const AgentAdjoint* a, std::span<int> nbrs, int j, Planar& kt, Planar& dt,
                       bool summed_weights = false) const;

 private:
  // Running sums of one agent's pair terms, and one pair's terms added to them: avoidance (for a neighbour
  // within its radius), then matching and centering (returning the pair's squared distance).
  struct ForwardSum;
  struct TransposedSum;
  void forward_avoidance(const AgentMotion& ai, const AgentMotion& aj, ForwardSum& sum) const;
  double forward_matching_centering(const AgentMotion& ai, const AgentMotion& aj, ForwardSum& sum) const;
  void transposed_avoidance(const AgentAdjoint& aj, const AgentAdjoint& ai, TransposedSum& sum) const;
  template <bool kSummedWeights>
  double transposed_matching_centering(const AgentAdjoint& aj, const AgentAdjoint& ai, TransposedSum& sum) const;
  template <bool kSummedWeights>
  void transposed_sums(const AgentAdjoint* a, std::span<int> nbrs, int j, TransposedSum& sum) const;
#ifdef KF_FLOCK_AVX512
  // The same sums, eight neighbours at a time (neighbor_forces_eight_wide.cpp).
  void forward_eight_wide(const AgentMotion* a, std::span<const int> nbrs, int i, ForwardSum& sum) const;
  template <bool kSummedWeights>
  void transposed_eight_wide(const AgentAdjoint* a, std::span<const int> nbrs, int j, TransposedSum& sum) const;
#endif

  double ka_, kmatch_, kc_;             // strengths
  double ra2_, rm2_, rc2_;              // squared radii, 0 for a term that is off
  double inv_ra2_, inv_rm2_, inv_rc2_;  // 1/R^2 of each term
  double eps2_;                         // avoidance softening^2 (m^2)
  // Matching and centering both on with one radius: a pair's kernel weight serves both (the same value).
  bool same_mc_;
  double radius_ = 0;
};

}  // namespace kf

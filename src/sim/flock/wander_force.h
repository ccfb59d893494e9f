#pragma once
// Wander: a seeded random horizontal force per agent that varies smoothly over time.
//
// Each agent draws independent values in [-1, 1] (x and z) at knots every `correlation_steps` steps and
// blends them with a C1 smoothstep; the force is strength x that. Values come from a counter-based hash
// of (seed, agent, knot), so the force is a fixed function of (agent, step): the same for every
// optimisation iteration and any thread count. It is tabulated once at construction (the paper stores
// all wander forces); steps beyond the table are evaluated from the same formula.
// Independent of x and v: K = D = 0.
#include <vector>

#include "sim/flock/flock_force.h"

namespace kf {

struct WanderParams {
  double strength;        // N
  int correlation_steps;  // knot spacing, in steps of length h_ref
  unsigned seed;
  double step_ratio = 1;  // h / h_ref: with a finer step the same force is seen at the same times
};

// The wander force (N, y = 0) on `agent` during step n.
Vec3 wander_value(const WanderParams& p, int agent, int n);

class WanderForce final : public FlockForce {
 public:
  // Tabulates steps 0..steps-1 for p agents (up to a memory cap).
  WanderForce(WanderParams p, int agents, int steps);
  const char* name() const override { return "wander"; }
  void add_force(const FlockState& s, int i, Vec3& f) const override;

 private:
  WanderParams p_;
  int agents_, tabulated_steps_;
  std::vector<double> table_;  // [step][agent][x, z]
};

}  // namespace kf

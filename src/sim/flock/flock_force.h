#pragma once
// One force term of a flock, evaluated per agent so the system can run agents in parallel.
//
// Each agent's output is a gather over its own neighbour list (it writes only its own entry), which
// keeps results bit-identical for any thread count. Jacobians are never assembled: the adjoint needs
// only K^T y and D^T y (K = df/dx, D = df/dv, y a 3p vector), which each term applies matrix-free.
#include "core/types.h"
#include "sim/flock/neighbor_lists.h"

namespace kf {

// The state a force is evaluated at: step n, positions x and velocities v (3p each), neighbours of x
// within the largest force radius.
struct FlockState {
  int step;
  const VecX& x;
  const VecX& v;
  const NeighborLists& neighbors;
};

class FlockForce {
 public:
  virtual ~FlockForce() = default;
  virtual const char* name() const = 0;
  // Distance (m) beyond which agents do not interact through this term; 0 when it needs no neighbours.
  virtual double radius() const { return 0; }
  // Per-agent quantities other agents' entries depend on (centering's neighbourhood means). Called once
  // per state before the per-agent calls below; may run in parallel inside.
  virtual void prepare(const FlockState& s) {}
  // Adds the force on agent i (N).
  virtual void add_force(const FlockState& s, int i, Vec3& f) const = 0;
  // Adds (K^T y)_j and (D^T y)_j, entry j of the transposed Jacobians applied to y (3p).
  virtual void add_KT(const FlockState& s, const VecX& y, int j, Vec3& out) const {}
  virtual void add_DT(const FlockState& s, const VecX& y, int j, Vec3& out) const {}
};

}  // namespace kf

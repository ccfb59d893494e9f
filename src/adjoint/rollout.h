#pragma once
// Forward simulation that keeps every state, and the adjoint pass that walks it backwards.
#include <vector>

#include "core/types.h"
#include "sim/system.h"

namespace kf {

// States x_0..x_N and v_0..v_N of one simulation (N steps, each 3p).
struct Rollout {
  std::vector<VecX> x, v;
  int diverged_at = -1;  // first step whose result was not finite, or -1
  int steps() const { return int(x.size()) - 1; }
};

// A sum of terms g_n(x_n, v_n) over steps; zero at most steps.
class StateCost {
 public:
  virtual ~StateCost() = default;
  virtual bool active(int n) const = 0;
  // Returns g_n and adds dg_n/dx_n to gx and dg_n/dv_n to gv (both 3p).
  virtual double eval(int n, const VecX& x, const VecX& v, VecX& gx, VecX& gv) const = 0;
};

// Runs N = U.size() steps from (x0, v0) under per-step control forces U. Returns false (and sets
// diverged_at) when a step fails; states after it are left as they were.
bool simulate(System& sys, const VecX& x0, const VecX& v0, const std::vector<VecX>& U, Rollout& r);

// Sum of the cost over the rollout's states.
double cost_value(const StateCost& cost, const Rollout& r);

// Adjoint pass: dU[n] = dphi/du_n through the dynamics, dx0/dv0 = dphi/dx_0, dphi/dv_0.
void backward(System& sys, const Rollout& r, const std::vector<VecX>& U, const StateCost& cost,
              std::vector<VecX>& dU, VecX& dx0, VecX& dv0);

}  // namespace kf

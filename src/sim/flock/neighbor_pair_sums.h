#pragma once
// The running sums of one agent's neighbour pair terms, shared by NeighborForces' scalar passes and its
// eight-wide ones (neighbor_forces_eight_wide.cpp), which add their terms to them in the same order.
#include "sim/flock/neighbor_forces.h"

namespace kf {

// (x, z) pairs: every operation acts on both components at once, in the same order and with the same
// operands as the scalar formula of each component, so the results are bit for bit those of the scalar
// formulas (no fused multiply-add). A pair's sums over components (r^2, dot products) add x then z.
typedef double Pair2 __attribute__((vector_size(16)));

inline Pair2 pair(double x, double z) { return Pair2{x, z}; }
inline double dot2(Pair2 a, Pair2 b) {
  const Pair2 m = a * b;
  return m[0] + m[1];
}

// One agent's forward terms (before strengths): avoidance sum w g d in a, matching w (v_j - v_i) in m and
// its weights in wm, centering's a_i = -sum w d in c and b_i = 1 + sum w in w (the agent's own weight 1);
// d = x_i - x_j.
struct NeighborForces::ForwardSum {
  Pair2 a{0, 0}, m{0, 0}, c{0, 0};
  double w = 1.0, wm = 0;
};

// One agent's transposed terms (before strengths): avoidance and matching shares of K^T y, matching's of
// D^T y, centering's of K^T y, and the summed weights' derivative weighted by q.
struct NeighborForces::TransposedSum {
  Pair2 ka{0, 0}, km{0, 0}, dm{0, 0}, kc{0, 0}, kq{0, 0};
};

}  // namespace kf

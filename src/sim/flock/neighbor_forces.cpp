#include "sim/flock/neighbor_forces.h"

#include <algorithm>
#include <cmath>

#include "sim/flock/avoidance_force.h"
#include "sim/flock/smooth_kernel.h"

namespace kf {

namespace {
double squared_radius(double strength, double radius) { return strength == 0 ? 0.0 : radius * radius; }
}  // namespace

NeighborForces::NeighborForces(const FlockSpec& s)
    : ka_(s.avoidance.strength),
      kmatch_(s.matching.strength),
      kc_(s.centering.strength),
      ra2_(squared_radius(ka_, s.avoidance.radius)),
      rm2_(squared_radius(kmatch_, s.matching.radius)),
      rc2_(squared_radius(kc_, s.centering.radius)),
      inv_ra2_(1.0 / (s.avoidance.radius * s.avoidance.radius)),
      inv_rm2_(1.0 / (s.matching.radius * s.matching.radius)),
      inv_rc2_(1.0 / (s.centering.radius * s.centering.radius)),
      eps2_(AvoidancePair::kSoftening * AvoidancePair::kSoftening * (s.avoidance.radius * s.avoidance.radius)),
      same_mc_(rm2_ > 0 && rm2_ == rc2_ && inv_rm2_ == inv_rc2_) {
  if (ka_ > 0) radius_ = std::max(radius_, s.avoidance.radius);
  if (kmatch_ > 0) radius_ = std::max(radius_, s.matching.radius);
  if (kc_ > 0) radius_ = std::max(radius_, s.centering.radius);
}

// d = x_i - x_j. Avoidance, for a neighbour within its radius: w g d.
inline void NeighborForces::forward_avoidance(const AgentMotion& ai, const AgentMotion& aj, PairForward& q) const {
  const double dx = ai.x - aj.x, dz = ai.z - aj.z;
  const double r2 = dx * dx + dz * dz;
  const KernelWeight k = smooth_kernel_inv(r2, inv_ra2_);
  const double wg = k.w / std::sqrt(r2 + eps2_);
  q.ax = wg * dx;
  q.az = wg * dz;
}

// Matching and centering; returns r2. The branches skip terms out of reach (their kernel weight is zero
// there anyway); when the list's radius is theirs, they are always taken.
inline double NeighborForces::forward_matching_centering(const AgentMotion& ai, const AgentMotion& aj,
                                                         PairForward& q) const {
  const double dx = ai.x - aj.x, dz = ai.z - aj.z;
  const double r2 = dx * dx + dz * dz;
  double wm = 0;
  if (r2 < rm2_) {  // matching: w (v_j - v_i)
    wm = smooth_kernel_inv(r2, inv_rm2_).w;
    q.mx = wm * (aj.vx - ai.vx);
    q.mz = wm * (aj.vz - ai.vz);
  }
  if (r2 < rc2_) {  // centering sums: a -= w d, b += w
    const double w = same_mc_ ? wm : smooth_kernel_inv(r2, inv_rc2_).w;
    q.cx = w * dx;
    q.cz = w * dz;
    q.w = w;
  }
  return r2;
}

// d = x_j - x_i. Avoidance, for a neighbour within its radius: J(d) e with e = y_j - y_i,
// J = w g I + 2 (w' g + w g') d d^T, g = (r2 + eps^2)^-1/2.
inline void NeighborForces::transposed_avoidance(const AgentAdjoint& aj, const AgentAdjoint& ai,
                                                 PairTransposed& q) const {
  const double dx = aj.x - ai.x, dz = aj.z - ai.z;
  const double r2 = dx * dx + dz * dz;
  const KernelWeight k = smooth_kernel_inv(r2, inv_ra2_);
  const double g = 1.0 / std::sqrt(r2 + eps2_);
  const double ex = aj.yx - ai.yx, ez = aj.yz - ai.yz;
  const double wg = k.w * g, s = 2.0 * (k.dw_dr2 * g - 0.5 * k.w * g * g * g) * (dx * ex + dz * ez);
  q.kax = wg * ex + s * dx;
  q.kaz = wg * ez + s * dz;
}

// Matching and centering; returns r2.
inline double NeighborForces::transposed_matching_centering(const AgentAdjoint& aj, const AgentAdjoint& ai,
                                                            PairTransposed& q) const {
  const double dx = aj.x - ai.x, dz = aj.z - ai.z;
  const double r2 = dx * dx + dz * dz;
  KernelWeight km;
  if (r2 < rm2_) {
    // K^T: 2 w' ((v_i - v_j) . (y_j - y_i)) d;  D^T: w (y_i - y_j).
    const KernelWeight k = km = smooth_kernel_inv(r2, inv_rm2_);
    const double s = 2.0 * k.dw_dr2 * ((ai.vx - aj.vx) * (aj.yx - ai.yx) + (ai.vz - aj.vz) * (aj.yz - ai.yz));
    q.kmx = s * dx;
    q.kmz = s * dz;
    q.dmx = k.w * (ai.yx - aj.yx);
    q.dmz = k.w * (ai.yz - aj.yz);
  }
  if (r2 < rc2_) {
    // (d f_i/d x_j)^T y_i - (d f_j/d x_i)^T y_j with g_i = -2 w' d (CenteringPair::add_KT).
    const KernelWeight k = same_mc_ ? km : smooth_kernel_inv(r2, inv_rc2_);
    const double gx = -2.0 * k.dw_dr2 * dx, gz = -2.0 * k.dw_dr2 * dz;
    const double si = (ai.ox - dx) * ai.yx + (ai.oz - dz) * ai.yz;
    const double sj = (dx + aj.ox) * aj.yx + (dz + aj.oz) * aj.yz;
    q.kcx = ai.c_over_b * (k.w * ai.yx + si * gx) - aj.c_over_b * (k.w * aj.yx - sj * gx);
    q.kcz = ai.c_over_b * (k.w * ai.yz + si * gz) - aj.c_over_b * (k.w * aj.yz - sj * gz);
  }
  return r2;
}

namespace {

// Running sums of one agent's pair terms. The centering sum a_i is kept in (cx, cz) with the sign of
// PairForward (subtracted), b starts at the agent's own weight 1.
struct ForwardSum {
  PairForward s{0, 0, 0, 0, 0, 0, 1.0};
  void add(const PairForward& q) {
    s.ax += q.ax, s.az += q.az, s.mx += q.mx, s.mz += q.mz, s.cx -= q.cx, s.cz -= q.cz, s.w += q.w;
  }
};

struct TransposedSum {
  PairTransposed s;
  void add(const PairTransposed& q) {
    s.kax += q.kax, s.kaz += q.kaz, s.kmx += q.kmx, s.kmz += q.kmz;
    s.dmx += q.dmx, s.dmz += q.dmz, s.kcx += q.kcx, s.kcz += q.kcz;
  }
};

}  // namespace

Planar NeighborForces::finish_force(const PairForward& sum, Planar& offset_i, double& b_i) const {
  offset_i = {sum.cx / sum.w, sum.cz / sum.w};
  b_i = sum.w;
  return {ka_ * sum.ax + kmatch_ * sum.mx + kc_ * offset_i.x, ka_ * sum.az + kmatch_ * sum.mz + kc_ * offset_i.z};
}

void NeighborForces::finish_transposed(const PairTransposed& sum, Planar& kt, Planar& dt) const {
  kt = {ka_ * sum.kax + kmatch_ * sum.kmx + sum.kcx, ka_ * sum.kaz + kmatch_ * sum.kmz + sum.kcz};
  dt = {kmatch_ * sum.dmx, kmatch_ * sum.dmz};
}

// Two passes over the list, so that no branch depends on whether a neighbour is within the avoidance radius
// (about a third are, in no predictable order): matching and centering over every neighbour (`every` adds
// neighbour j's to q and returns r2), moving those within the avoidance radius to the front of the list as it
// goes, then avoidance over those (`near`). Each sum still adds its nonzero terms in list order, and a term a
// pass skips is +0, which leaves a sum unchanged: the results are bit for bit those of one pass with branches.
namespace {
template <class Pair, class Sum, class Every, class Near>
void sum_in_two_passes(std::span<int> nbrs, double ra2, Sum& sum, Every every, Near near) {
  size_t within = 0;
  for (int j : nbrs) {
    Pair q;
    const double r2 = every(j, q);
    sum.add(q);
    nbrs[within] = j;
    within += size_t(r2 < ra2);
  }
  for (size_t e = 0; e < within; ++e) {
    Pair q;
    near(nbrs[e], q);
    sum.add(q);
  }
}
}  // namespace

Planar NeighborForces::force(const AgentMotion* a, std::span<int> nbrs, int i, Planar& offset_i,
                             double& b_i) const {
  ForwardSum sum;
  sum_in_two_passes<PairForward>(
      nbrs, ra2_, sum, [&](int j, PairForward& q) { return forward_matching_centering(a[i], a[j], q); },
      [&](int j, PairForward& q) { forward_avoidance(a[i], a[j], q); });
  return finish_force(sum.s, offset_i, b_i);
}

void NeighborForces::transpose_apply(const AgentAdjoint* a, std::span<int> nbrs, int j, Planar& kt,
                                     Planar& dt) const {
  TransposedSum sum;
  sum_in_two_passes<PairTransposed>(
      nbrs, ra2_, sum, [&](int i, PairTransposed& q) { return transposed_matching_centering(a[j], a[i], q); },
      [&](int i, PairTransposed& q) { transposed_avoidance(a[j], a[i], q); });
  finish_transposed(sum.s, kt, dt);
}

}  // namespace kf

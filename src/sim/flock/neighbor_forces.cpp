#include "sim/flock/neighbor_forces.h"

#include <algorithm>
#include <cmath>

#include "sim/flock/avoidance_force.h"
#include "sim/flock/flock_simd.h"
#include "sim/flock/neighbor_pair_sums.h"
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

// Matching and centering of neighbour j, added to agent i's sums; returns r2. With p = x_j - x_i = -d:
// w (v_j - v_i) is added to m, and a_i -= w d is a_i += w p. The branches skip terms out of reach (their
// kernel weight is zero there anyway); when the list's radius is theirs, they are always taken.
inline double NeighborForces::forward_matching_centering(const AgentMotion& ai, const AgentMotion& aj,
                                                         ForwardSum& sum) const {
  const Pair2 p = pair(aj.x, aj.z) - pair(ai.x, ai.z);
  const double r2 = dot2(p, p);
  double wm = 0;
  if (r2 < rm2_) {
    wm = smooth_kernel_inv(r2, inv_rm2_).w;
    sum.m += wm * (pair(aj.vx, aj.vz) - pair(ai.vx, ai.vz));
    sum.wm += wm;
  }
  if (r2 < rc2_) {
    const double w = same_mc_ ? wm : smooth_kernel_inv(r2, inv_rc2_).w;
    sum.c += w * p;
    sum.w += w;
  }
  return r2;
}

// Avoidance of neighbour j within its radius: w g d, g = (r2 + eps^2)^-1/2, added as a -= w g p.
inline void NeighborForces::forward_avoidance(const AgentMotion& ai, const AgentMotion& aj, ForwardSum& sum) const {
  const Pair2 p = pair(aj.x, aj.z) - pair(ai.x, ai.z);
  const double r2 = dot2(p, p);
  const KernelWeight k = smooth_kernel_inv(r2, inv_ra2_);
  sum.a -= (k.w / std::sqrt(r2 + eps2_)) * p;
}

// Matching and centering of neighbour i, added to agent j's transposed sums; returns r2. d = x_j - x_i.
template <bool kSummedWeights>
inline double NeighborForces::transposed_matching_centering(const AgentAdjoint& aj, const AgentAdjoint& ai,
                                                            TransposedSum& sum) const {
  const Pair2 d = pair(aj.x, aj.z) - pair(ai.x, ai.z);
  const double r2 = dot2(d, d);
  KernelWeight km;
  if (r2 < rm2_) {
    // K^T: 2 w' ((v_i - v_j) . (y_j - y_i)) d;  D^T: w (y_i - y_j).
    const KernelWeight k = km = smooth_kernel_inv(r2, inv_rm2_);
    const Pair2 yi = pair(ai.yx, ai.yz), yj = pair(aj.yx, aj.yz);
    const double s = 2.0 * k.dw_dr2 * dot2(pair(ai.vx, ai.vz) - pair(aj.vx, aj.vz), yj - yi);
    sum.km += s * d;
    sum.dm += k.w * (yi - yj);
    // w_ij is in S_i and S_j, and d w_ij / d x_j = 2 w' d.
    if constexpr (kSummedWeights) sum.kq += (2.0 * k.dw_dr2 * (ai.q + aj.q)) * d;
  }
  if (r2 < rc2_) {
    // (d f_i/d x_j)^T y_i - (d f_j/d x_i)^T y_j with g_i = -2 w' d (CenteringPair::add_KT).
    const KernelWeight k = same_mc_ ? km : smooth_kernel_inv(r2, inv_rc2_);
    const Pair2 yi = pair(ai.yx, ai.yz), yj = pair(aj.yx, aj.yz);
    const Pair2 g = -2.0 * k.dw_dr2 * d;
    const double si = dot2(pair(ai.ox, ai.oz) - d, yi), sj = dot2(d + pair(aj.ox, aj.oz), yj);
    sum.kc += ai.c_over_b * (k.w * yi + si * g) - aj.c_over_b * (k.w * yj - sj * g);
  }
  return r2;
}

// Avoidance of neighbour i within its radius: J(d) e with e = y_j - y_i,
// J = w g I + 2 (w' g + w g') d d^T, g = (r2 + eps^2)^-1/2.
inline void NeighborForces::transposed_avoidance(const AgentAdjoint& aj, const AgentAdjoint& ai,
                                                 TransposedSum& sum) const {
  const Pair2 d = pair(aj.x, aj.z) - pair(ai.x, ai.z);
  const double r2 = dot2(d, d);
  const KernelWeight k = smooth_kernel_inv(r2, inv_ra2_);
  const double g = 1.0 / std::sqrt(r2 + eps2_);
  const Pair2 e = pair(aj.yx, aj.yz) - pair(ai.yx, ai.yz);
  const double wg = k.w * g, s = 2.0 * (k.dw_dr2 * g - 0.5 * k.w * g * g * g) * dot2(d, e);
  sum.ka += wg * e + s * d;
}

// Two passes over the list, so that no branch depends on whether a neighbour is within the avoidance radius
// (about a third are, in no predictable order): matching and centering over every neighbour (`every` adds
// neighbour j's terms and returns r2), moving those within the avoidance radius to the front of the list as it
// goes, then avoidance over those (`near`). Each sum adds its terms in list order, and a term a pass skips
// would be +0, which leaves a sum unchanged: the results are bit for bit those of one pass with branches.
namespace {
template <class Every, class Near>
void sum_in_two_passes(std::span<int> nbrs, double ra2, Every every, Near near) {
  size_t within = 0;
  for (int j : nbrs) {
    const double r2 = every(j);
    nbrs[within] = j;
    within += size_t(r2 < ra2);
  }
  for (size_t e = 0; e < within; ++e) near(nbrs[e]);
}
}  // namespace

Planar NeighborForces::force(const AgentMotion* a, std::span<int> nbrs, int i, Planar& offset_i, double& b_i,
                             double& damping_i) const {
  ForwardSum sum;
#ifdef KF_FLOCK_AVX512
  if (flock_simd_enabled()) {
    forward_eight_wide(a, nbrs, i, sum);
  } else
#endif
  {
    sum_in_two_passes(
        nbrs, ra2_, [&](int j) { return forward_matching_centering(a[i], a[j], sum); },
        [&](int j) { forward_avoidance(a[i], a[j], sum); });
  }
  offset_i = {sum.c[0] / sum.w, sum.c[1] / sum.w};
  b_i = sum.w;
  damping_i = kmatch_ * sum.wm;
  return {ka_ * sum.a[0] + kmatch_ * sum.m[0] + kc_ * offset_i.x,
          ka_ * sum.a[1] + kmatch_ * sum.m[1] + kc_ * offset_i.z};
}

template <bool kSummedWeights>
void NeighborForces::transposed_sums(const AgentAdjoint* a, std::span<int> nbrs, int j, TransposedSum& sum) const {
#ifdef KF_FLOCK_AVX512
  if (flock_simd_enabled()) return transposed_eight_wide<kSummedWeights>(a, nbrs, j, sum);
#endif
  sum_in_two_passes(
      nbrs, ra2_, [&](int i) { return transposed_matching_centering<kSummedWeights>(a[j], a[i], sum); },
      [&](int i) { transposed_avoidance(a[j], a[i], sum); });
}

void NeighborForces::transpose_apply(const AgentAdjoint* a, std::span<int> nbrs, int j, Planar& kt, Planar& dt,
                                     bool summed_weights) const {
  TransposedSum sum;
  if (summed_weights) {
    transposed_sums<true>(a, nbrs, j, sum);
  } else {
    transposed_sums<false>(a, nbrs, j, sum);
  }
  kt = {ka_ * sum.ka[0] + kmatch_ * sum.km[0] + sum.kc[0], ka_ * sum.ka[1] + kmatch_ * sum.km[1] + sum.kc[1]};
  if (summed_weights) kt = {kt.x + sum.kq[0], kt.z + sum.kq[1]};
  dt = {kmatch_ * sum.dm[0], kmatch_ * sum.dm[1]};
}

}  // namespace kf

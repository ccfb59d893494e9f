#include "sim/flock/neighbor_forces.h"

#include <algorithm>
#include <cmath>

#include "sim/flock/avoidance_force.h"
#include "sim/flock/parallel_agents.h"
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
      eps2_(AvoidancePair::kSoftening * AvoidancePair::kSoftening * (s.avoidance.radius * s.avoidance.radius)) {
  if (ka_ > 0) radius_ = std::max(radius_, s.avoidance.radius);
  if (kmatch_ > 0) radius_ = std::max(radius_, s.matching.radius);
  if (kc_ > 0) radius_ = std::max(radius_, s.centering.radius);
}

Planar NeighborForces::force(const AgentMotion* a, std::span<const int> nbrs, int i, Planar& offset_i,
                             double& b_i) const {
  const AgentMotion ai = a[i];
  double fax = 0, faz = 0, fmx = 0, fmz = 0, cx = 0, cz = 0, b = 1.0;
  for (int j : nbrs) {
    const AgentMotion& aj = a[j];
    const double dx = ai.x - aj.x, dz = ai.z - aj.z;  // x_i - x_j
    const double r2 = dx * dx + dz * dz;
    if (r2 < ra2_) {  // avoidance: w g d
      const KernelWeight k = smooth_kernel_inv(r2, inv_ra2_);
      const double wg = k.w / std::sqrt(r2 + eps2_);
      fax += wg * dx;
      faz += wg * dz;
    }
    if (r2 < rm2_) {  // matching: w (v_j - v_i)
      const double w = smooth_kernel_inv(r2, inv_rm2_).w;
      fmx += w * (aj.vx - ai.vx);
      fmz += w * (aj.vz - ai.vz);
    }
    if (r2 < rc2_) {  // centering sums: a -= w d, b += w
      const double w = smooth_kernel_inv(r2, inv_rc2_).w;
      cx -= w * dx;
      cz -= w * dz;
      b += w;
    }
  }
  offset_i = {cx / b, cz / b};
  b_i = b;
  return {ka_ * fax + kmatch_ * fmx + kc_ * offset_i.x, ka_ * faz + kmatch_ * fmz + kc_ * offset_i.z};
}

void NeighborForces::centering(const AgentMotion* a, std::span<const int> nbrs, int i, Planar& offset_i,
                               double& b_i) const {
  const AgentMotion ai = a[i];
  double cx = 0, cz = 0, b = 1.0;
  for (int j : nbrs) {
    const double dx = ai.x - a[j].x, dz = ai.z - a[j].z;
    const double r2 = dx * dx + dz * dz;
    if (r2 < rc2_) {
      const double w = smooth_kernel_inv(r2, inv_rc2_).w;
      cx -= w * dx;
      cz -= w * dz;
      b += w;
    }
  }
  offset_i = {cx / b, cz / b};
  b_i = b;
}

void NeighborForces::transpose_apply(const AgentAdjoint* a, std::span<const int> nbrs, int j, Planar& kt,
                                     Planar& dt) const {
  const AgentAdjoint aj = a[j];
  double kax = 0, kaz = 0, kmx = 0, kmz = 0, kcx = 0, kcz = 0, dmx = 0, dmz = 0;
  for (int i : nbrs) {
    const AgentAdjoint& ai = a[i];
    const double dx = aj.x - ai.x, dz = aj.z - ai.z;  // x_j - x_i
    const double r2 = dx * dx + dz * dz;
    if (r2 < ra2_) {
      // J(d) e with e = y_j - y_i: J = w g I + 2 (w' g + w g') d d^T, g = (r2 + eps^2)^-1/2.
      const KernelWeight k = smooth_kernel_inv(r2, inv_ra2_);
      const double g = 1.0 / std::sqrt(r2 + eps2_);
      const double ex = aj.yx - ai.yx, ez = aj.yz - ai.yz;
      const double wg = k.w * g, s = 2.0 * (k.dw_dr2 * g - 0.5 * k.w * g * g * g) * (dx * ex + dz * ez);
      kax += wg * ex + s * dx;
      kaz += wg * ez + s * dz;
    }
    if (r2 < rm2_) {
      // K^T: 2 w' ((v_i - v_j) . (y_j - y_i)) d;  D^T: w (y_i - y_j).
      const KernelWeight k = smooth_kernel_inv(r2, inv_rm2_);
      const double s = 2.0 * k.dw_dr2 * ((ai.vx - aj.vx) * (aj.yx - ai.yx) + (ai.vz - aj.vz) * (aj.yz - ai.yz));
      kmx += s * dx;
      kmz += s * dz;
      dmx += k.w * (ai.yx - aj.yx);
      dmz += k.w * (ai.yz - aj.yz);
    }
    if (r2 < rc2_) {
      // (d f_i/d x_j)^T y_i - (d f_j/d x_i)^T y_j with g_i = -2 w' d (CenteringPair::add_KT).
      const KernelWeight k = smooth_kernel_inv(r2, inv_rc2_);
      const double gx = -2.0 * k.dw_dr2 * dx, gz = -2.0 * k.dw_dr2 * dz;
      const double si = (ai.ox - dx) * ai.yx + (ai.oz - dz) * ai.yz;
      const double sj = (dx + aj.ox) * aj.yx + (dz + aj.oz) * aj.yz;
      kcx += ai.c_over_b * (k.w * ai.yx + si * gx) - aj.c_over_b * (k.w * aj.yx - sj * gx);
      kcz += ai.c_over_b * (k.w * ai.yz + si * gz) - aj.c_over_b * (k.w * aj.yz - sj * gz);
    }
  }
  kt = {ka_ * kax + kmatch_ * kmx + kcx, ka_ * kaz + kmatch_ * kmz + kcz};
  dt = {kmatch_ * dmx, kmatch_ * dmz};
}

void pack_motion(const VecX& x, const VecX& v, std::vector<AgentMotion>& a) {
  parallel_agents(int(a.size()), [&](int i) { a[i] = {x[3 * i], x[3 * i + 2], v[3 * i], v[3 * i + 2]}; });
}

}  // namespace kf

#pragma once
// Shared checks of the stability suite: finite states and the energy bound of a dissipative cloth.
#include <gtest/gtest.h>

#include "adjoint/rollout.h"
#include "sim/system.h"

namespace kf::test {

// Kinetic plus gravitational potential energy (J) for gravity g along -y (m/s^2).
inline double mechanical_energy(const System& s, const VecX& x, const VecX& v, double g) {
  double e = 0;
  for (int i = 0; i < s.particles(); ++i) e += s.masses()[i] * (0.5 * seg(v, i).squaredNorm() + g * x[3 * i + 1]);
  return e;
}

// Every kept state finite.
inline ::testing::AssertionResult all_finite(const Rollout& r) {
  for (int n = 0; n <= r.steps(); ++n)
    if (r.kept(n) && !(r.x[n].allFinite() && r.v[n].allFinite()))
      return ::testing::AssertionFailure() << "state " << n << " is not finite";
  return ::testing::AssertionSuccess();
}

// A cloth stepped by backward Euler with damping and without controls never gains energy: elastic and
// contact energies are >= 0 and start at 0, so kinetic + gravitational energy stays below its start.
inline ::testing::AssertionResult energy_bounded(const System& s, const Rollout& r, double g, double slack) {
  const double e0 = mechanical_energy(s, r.x[0], r.v[0], g);
  for (int n = 1; n <= r.steps(); ++n) {
    if (!r.kept(n)) continue;
    const double e = mechanical_energy(s, r.x[n], r.v[n], g);
    if (e > e0 + slack)
      return ::testing::AssertionFailure() << "energy " << e << " J at step " << n << " above the start " << e0 << " J";
  }
  return ::testing::AssertionSuccess();
}

}  // namespace kf::test

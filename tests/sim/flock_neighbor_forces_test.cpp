// The fused neighbour pass (NeighborForces) against the three force terms it fuses, evaluated one by one,
// and the record reuse of the flock's adjoint step.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "sim/flock/avoidance_force.h"
#include "sim/flock/centering_force.h"
#include "sim/flock/flock_simd.h"
#include "sim/flock/flock_system.h"
#include "sim/flock/matching_force.h"
#include "sim/flock/neighbor_forces.h"
#include "random_flock.h"

namespace kf {
namespace {

TEST(NeighborForces, EqualsTheSeparateTermsForwardAndTransposed) {
  const int p = 60;
  std::mt19937_64 rng(9);
  const VecX x = random_planar(p, 4.0, rng), v = random_planar(p, 1.0, rng), y = random_planar(p, 1.0, rng);
  // Every radius different, then matching and centering sharing one (their kernel weight computed once).
  for (const double rc : {3.5, 2.5}) {
    FlockSpec spec;
    spec.agents = p;
    spec.avoidance = {6.0, 1.5};
    spec.matching = {0.5, 2.5};
    spec.centering = {1.0, rc};
    NeighborForces fused(spec);
    ASSERT_EQ(fused.radius(), rc);
    NeighborGrid grid;
    grid.build(x, fused.radius());
    AvoidanceForce avoid({6.0, 1.5});
    MatchingForce match({0.5, 2.5});
    CenteringForce centre({1.0, rc});
    const FlockState s{0, x, v, grid.lists()};
    centre.prepare(s);
    std::vector<AgentMotion> motion(p);
    for (int i = 0; i < p; ++i) motion[i] = {x[3 * i], x[3 * i + 2], v[3 * i], v[3 * i + 2]};
    std::vector<Planar> offset(p);
    std::vector<double> b(p);
    double largest = 0;
    for (int i = 0; i < p; ++i) {
      Vec3 f_ref = Vec3::Zero();
      std::vector<int> list(grid.neighbors(i).begin(), grid.neighbors(i).end());  // the pass reorders it
      double damping = 0;
      const Planar fp = fused.force(motion.data(), list, i, offset[i], b[i], damping);
      const Vec3 f(fp.x, 0, fp.z);
      avoid.add_force(s, i, f_ref);
      match.add_force(s, i, f_ref);
      centre.add_force(s, i, f_ref);
      largest = std::max(largest, f_ref.norm());
      EXPECT_LT((f - f_ref).norm(), 1e-12 * (1 + f_ref.norm())) << "agent " << i;
      // Matching's own damping is -D_ii: (D^T e_i)_i with e_i agent i's x direction.
      VecX e = VecX::Zero(3 * p);
      e[3 * i] = 1;
      Vec3 de = Vec3::Zero();
      match.add_DT(s, e, i, de);
      EXPECT_NEAR(damping, -de.x(), 1e-12 * (1 + damping)) << "agent " << i;
    }
    ASSERT_GT(largest, 0.1);
    std::vector<AgentAdjoint> adjoint(p);
    for (int i = 0; i < p; ++i)
      adjoint[i] = {x[3 * i],     x[3 * i + 2], v[3 * i],    v[3 * i + 2], y[3 * i],
                    y[3 * i + 2], offset[i].x,  offset[i].z, 1.0 / b[i],   0.0};
    for (int j = 0; j < p; ++j) {
      Vec3 kt_ref = Vec3::Zero(), dt_ref = Vec3::Zero();
      Planar kp, dp;
      std::vector<int> list(grid.neighbors(j).begin(), grid.neighbors(j).end());
      fused.transpose_apply(adjoint.data(), list, j, kp, dp);
      const Vec3 kt(kp.x, 0, kp.z), dt(dp.x, 0, dp.z);
      avoid.add_KT(s, y, j, kt_ref);
      match.add_KT(s, y, j, kt_ref);
      centre.add_KT(s, y, j, kt_ref);
      match.add_DT(s, y, j, dt_ref);
      EXPECT_LT((kt - kt_ref).norm(), 1e-11 * (1 + kt_ref.norm())) << "agent " << j;
      EXPECT_LT((dt - dt_ref).norm(), 1e-11 * (1 + dt_ref.norm())) << "agent " << j;
    }
  }
}

// The eight-wide passes (AVX-512) against the scalar passes, compared bit for bit: forces, centering
// quantities and transposed products, with and without the summed-weights term, for lists of every length
// modulo 8, coincident agents and agents exactly at a cut-off, every radius different or shared, and a term off.
TEST(NeighborForces, EightWidePassesGiveTheScalarPassesBitForBit) {
  allow_flock_simd(true);
  if (!flock_simd_enabled()) GTEST_SKIP() << "no AVX-512 here";
  std::mt19937_64 rng(31);
  const int p = 400;
  VecX x = random_planar(p, 6.0, rng);
  for (int i = 0; i + 3 < p; i += 9) {
    seg(x, i + 1) = seg(x, i);
    seg(x, i + 2) = seg(x, i) + Vec3(1.5, 0, 0);  // exactly at the avoidance cut-off
    seg(x, i + 3) = seg(x, i) + Vec3(0, 0, 2.5 * (1 - 1e-16));
  }
  const VecX v = random_planar(p, 1.0, rng), y = random_planar(p, 1.0, rng), q = random_planar(p, 0.3, rng);
  struct Radii {
    double avoid, match, centre, match_strength;
  };
  long compared = 0;
  for (const Radii r :
       {Radii{1.5, 2.5, 2.5, 0.5}, Radii{1.5, 2.5, 3.5, 0.5}, Radii{3.0, 2.0, 2.5, 0.5}, Radii{1.5, 2.5, 2.5, 0.0}}) {
    FlockSpec spec;
    spec.agents = p;
    spec.avoidance = {6.0, r.avoid};
    spec.matching = {r.match_strength, r.match};
    spec.centering = {1.0, r.centre};
    const NeighborForces fused(spec);
    NeighborGrid grid;
    grid.build(x, fused.radius());
    std::vector<AgentMotion> motion(p);
    for (int i = 0; i < p; ++i) motion[i] = {x[3 * i], x[3 * i + 2], v[3 * i], v[3 * i + 2]};
    std::vector<AgentAdjoint> adjoint(p);
    for (const bool simd : {false, true}) {
      allow_flock_simd(simd);
      for (int i = 0; i < p; ++i) {
        std::vector<int> list(grid.neighbors(i).begin(), grid.neighbors(i).end());
        Planar offset;
        double b = 0, damping = 0;
        const Planar f = fused.force(motion.data(), list, i, offset, b, damping);
        const AgentAdjoint packed{x[3 * i],     x[3 * i + 2], v[3 * i], v[3 * i + 2], y[3 * i],
                                  y[3 * i + 2], offset.x,     offset.z, 1.0 / b,      q[3 * i]};
        if (!simd) {
          adjoint[i] = packed;
          continue;
        }
        const AgentAdjoint& scalar = adjoint[i];
        ASSERT_EQ(std::memcmp(&scalar, &packed, sizeof packed), 0) << "agent " << i;  // offset and b
        std::vector<int> again(grid.neighbors(i).begin(), grid.neighbors(i).end());
        allow_flock_simd(false);
        Planar offset0;
        double b0 = 0, damping0 = 0;
        const Planar f0 = fused.force(motion.data(), again, i, offset0, b0, damping0);
        allow_flock_simd(true);
        EXPECT_EQ(std::memcmp(&f, &f0, sizeof f), 0) << "agent " << i;
        EXPECT_EQ(std::memcmp(&damping, &damping0, sizeof damping), 0) << "agent " << i;
      }
    }
    for (int j = 0; j < p; ++j)
      for (const bool summed : {false, true}) {
        Planar kt[2], dt[2];
        for (const bool simd : {false, true}) {
          allow_flock_simd(simd);
          std::vector<int> list(grid.neighbors(j).begin(), grid.neighbors(j).end());
          fused.transpose_apply(adjoint.data(), list, j, kt[simd], dt[simd], summed);
        }
        EXPECT_EQ(std::memcmp(&kt[0], &kt[1], sizeof kt[0]), 0) << "agent " << j << " summed " << summed;
        EXPECT_EQ(std::memcmp(&dt[0], &dt[1], sizeof dt[0]), 0) << "agent " << j << " summed " << summed;
        compared += long(grid.neighbors(j).size());
      }
  }
  allow_flock_simd(true);
  EXPECT_GT(compared, 50000);
}

TEST(FlockSystem, AdjointStepIsTheSameWithAndWithoutTheForwardRecord) {
  const int p = 30;
  FlockSpec spec;
  spec.agents = p;
  spec.spawn.radius = 4;
  spec.spawn.velocity = Vec3(0.5, 0, 1);
  std::mt19937_64 rng(2);
  VecX x, v;
  FlockSystem a(spec, 1.0 / 30, 10, 3), b(spec, 1.0 / 30, 10, 3);
  a.initial_state(x, v);
  x += random_planar(p, 0.3, rng);
  const VecX u = random_planar(p, 0.5, rng), xh1 = random_planar(p, 1, rng), vh1 = random_planar(p, 1, rng);
  VecX x1, v1, xa, va, ua, xb, vb, ub;
  ASSERT_TRUE(a.step(4, x, v, u, x1, v1));  // a records step 4; b has never seen it
  a.step_adjoint(4, x, v, u, xh1, vh1, xa, va, ua);
  b.step_adjoint(4, x, v, u, xh1, vh1, xb, vb, ub);
  ASSERT_GT(xa.norm(), 0);
  EXPECT_EQ(xa, xb);
  EXPECT_EQ(va, vb);
  EXPECT_EQ(ua, ub);
  // A different state at the same step must not reuse the record.
  VecX x2 = x;
  x2[0] += 0.05;
  a.step_adjoint(4, x2, v, u, xh1, vh1, xa, va, ua);
  b.step_adjoint(4, x2, v, u, xh1, vh1, xb, vb, ub);
  EXPECT_EQ(xa, xb);
}

}  // namespace
}  // namespace kf

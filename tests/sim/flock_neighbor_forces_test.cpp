// The fused neighbour pass (NeighborForces) against the three force terms it fuses, evaluated one by one,
// and the record reuse of the flock's adjoint step.
#include <gtest/gtest.h>

#include <random>

#include "sim/flock/avoidance_force.h"
#include "sim/flock/centering_force.h"
#include "sim/flock/flock_system.h"
#include "sim/flock/matching_force.h"
#include "sim/flock/neighbor_forces.h"
#include "sim/flock/pair_index.h"
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
    pack_motion(x, v, motion);
    std::vector<Planar> offset(p);
    std::vector<double> b(p);
    double largest = 0;
    for (int i = 0; i < p; ++i) {
      Vec3 f_ref = Vec3::Zero();
      const Planar fp = fused.force(motion.data(), grid.neighbors(i), i, offset[i], b[i]);
      const Vec3 f(fp.x, 0, fp.z);
      avoid.add_force(s, i, f_ref);
      match.add_force(s, i, f_ref);
      centre.add_force(s, i, f_ref);
      largest = std::max(largest, f_ref.norm());
      EXPECT_LT((f - f_ref).norm(), 1e-12 * (1 + f_ref.norm())) << "agent " << i;
    }
    ASSERT_GT(largest, 0.1);
    std::vector<AgentAdjoint> adjoint(p);
    for (int i = 0; i < p; ++i)
      adjoint[i] = {x[3 * i], x[3 * i + 2], v[3 * i], v[3 * i + 2], y[3 * i], y[3 * i + 2], offset[i].x, offset[i].z, 1.0 / b[i]};
    for (int j = 0; j < p; ++j) {
      Vec3 kt_ref = Vec3::Zero(), dt_ref = Vec3::Zero();
      Planar kp, dp;
      fused.transpose_apply(adjoint.data(), grid.neighbors(j), j, kp, dp);
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

// Each pair once (owned lists, PairIndex, forward_pairs/transposed_pairs and the gathers) against the
// per-agent passes over whole lists: equal bit for bit, in a dense flock and in lists from a wrapped grid
// table.
TEST(NeighborForces, EachPairOnceEqualsWholeListsBitForBit) {
  std::mt19937_64 rng(4);
  FlockSpec spec;
  spec.avoidance = {6.0, 1.5};
  spec.matching = {0.5, 2.5};
  spec.centering = {1.0, 2.5};
  const NeighborForces fused(spec);
  for (const bool wrapped : {false, true}) {
    const int p = 500;
    VecX x = random_planar(p, 6.0, rng);  // ~50 neighbours each
    if (wrapped)  // a line far wider than the table, and a few strays far off
      for (int i = 0; i < p; ++i) x[3 * i] *= 300.0, x[3 * i + 2] *= 0.3;
    if (wrapped) seg(x, 7) = Vec3(-3e5, 0, 4e5), seg(x, 8) = Vec3(-3e5 + 0.3, 0, 4e5 - 0.2);
    const VecX v = random_planar(p, 1.0, rng), y = random_planar(p, 1.0, rng);
    NeighborGrid grid;
    grid.build(x, fused.radius());
    const NeighborLists& whole = grid.lists();
    NeighborLists lists;
    grid.search_owned(x, fused.radius(), lists);
    PairIndex index;
    index.build(lists);
    ASSERT_GT(index.pairs(), wrapped ? 100 : 5000);
    ASSERT_EQ(2 * lists.entries(), whole.entries());
    // Each whole list is the mirrored pairs' owners, then the owned neighbours: the later ones in the order.
    std::vector<int> rank(p);
    for (int k = 0; k < p; ++k) rank[lists.order()[k]] = k;
    std::vector<int> owner(index.pairs());
    for (int i = 0; i < p; ++i)
      for (int k = lists.start(i); k < lists.start(i + 1); ++k) owner[k] = i;
    for (int i = 0; i < p; ++i) {
      std::vector<int> joined;
      for (int k : index.mirrored(i)) joined.push_back(owner[k]);
      for (int k = lists.start(i); k < lists.start(i + 1); ++k) {
        ASSERT_GT(rank[lists.entry(k)], rank[i]);
        joined.push_back(lists.entry(k));
      }
      ASSERT_EQ(joined, std::vector<int>(whole.neighbors(i).begin(), whole.neighbors(i).end())) << "agent " << i;
    }

    std::vector<AgentMotion> motion(p);
    pack_motion(x, v, motion);
    std::vector<PairForward> fp(index.pairs());
    for (int i = 0; i < p; ++i) fused.forward_pairs(motion.data(), lists, index, i, fp.data());
    std::vector<Planar> offset(p);
    std::vector<double> b(p);
    for (int i = 0; i < p; ++i) {
      Planar o2;
      double b2;
      const Planar all = fused.force(motion.data(), whole.neighbors(i), i, offset[i], b[i]);
      const Planar once = fused.gather_force(lists, index, fp.data(), i, o2, b2);
      ASSERT_EQ(once.x, all.x) << "agent " << i;
      ASSERT_EQ(once.z, all.z) << "agent " << i;
      ASSERT_EQ(o2.x, offset[i].x);
      ASSERT_EQ(o2.z, offset[i].z);
      ASSERT_EQ(b2, b[i]);
    }
    std::vector<AgentAdjoint> adjoint(p);
    for (int i = 0; i < p; ++i)
      adjoint[i] = {x[3 * i], x[3 * i + 2], v[3 * i], v[3 * i + 2], y[3 * i], y[3 * i + 2], offset[i].x, offset[i].z, 1.0 / b[i]};
    std::vector<PairTransposed> tp(index.pairs());
    for (int j = 0; j < p; ++j) fused.transposed_pairs(adjoint.data(), lists, index, j, tp.data());
    double largest = 0;
    for (int j = 0; j < p; ++j) {
      Planar kw, dw, ko, d_o;
      fused.transpose_apply(adjoint.data(), whole.neighbors(j), j, kw, dw);
      fused.gather_transposed(lists, index, tp.data(), j, ko, d_o);
      ASSERT_EQ(ko.x, kw.x) << "agent " << j;
      ASSERT_EQ(ko.z, kw.z) << "agent " << j;
      ASSERT_EQ(d_o.x, dw.x) << "agent " << j;
      ASSERT_EQ(d_o.z, dw.z) << "agent " << j;
      largest = std::max(largest, std::abs(kw.x) + std::abs(dw.x));
    }
    EXPECT_GT(largest, 0.1);
  }
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

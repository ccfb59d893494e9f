// Hard flock cases: agents that start on top of each other, a long horizon.
#include <gtest/gtest.h>

#include "adjoint/rollout.h"
#include "scene/scene.h"
#include "sim/flock/flock_system.h"
#include "stability_util.h"
#include "../sim/random_flock.h"

namespace kf {
namespace {

FlockSpec flock_spec(int agents, double spawn_radius = 8) {
  return *parse_scene(R"({"flock": {"agents": )" + std::to_string(agents) + R"(, "spawn": {"radius": )" +
                          std::to_string(spawn_radius) + "}}}",
                      "f.json")
              .flock;
}

struct LastStateCost : StateCost {
  int N;
  explicit LastStateCost(int n) : N(n) {}
  bool active(int n) const override { return n == N; }
  double eval(int, const VecX& x, const VecX&, VecX& gx, VecX&) const override {
    gx += x;
    return 0.5 * x.squaredNorm();
  }
};

TEST(FlockStability, AgentsStartingOnTopOfEachOtherSpreadOut) {
  const FlockSpec spec = flock_spec(30);
  const int steps = 150;
  FlockSystem sys(spec, 1.0 / 30, steps, 3);
  VecX x0, v0;
  sys.initial_state(x0, v0);
  // Ten agents at exactly one point, ten pairs at zero distance elsewhere, the rest as spawned.
  for (int i = 1; i < 10; ++i) seg(x0, i) = seg(x0, 0);
  for (int i = 10; i < 30; i += 2) seg(x0, i + 1) = seg(x0, i);
  Rollout r;
  ASSERT_TRUE(simulate(sys, x0, v0, std::vector<VecX>(steps, VecX::Zero(sys.dof())), r)) << r.diverged_at;
  EXPECT_TRUE(test::all_finite(r));
  // Forces are bounded (softened avoidance) and drag limits speed: no energy blow-up.
  double vmax = 0;
  for (const auto& v : r.v) vmax = std::max(vmax, v.cwiseAbs().maxCoeff());
  EXPECT_LT(vmax, 20.0);
  double closest = 1e9;
  const VecX& x = r.x.back();
  for (int i = 0; i < 30; ++i)
    for (int j = i + 1; j < 30; ++j) closest = std::min(closest, (seg(x, i) - seg(x, j)).norm());
  EXPECT_GT(closest, 0.05) << "overlapping agents did not separate";
  // The adjoint through coincident agents is finite and not zero.
  LastStateCost cost(steps);
  std::vector<VecX> U(steps, VecX::Zero(sys.dof())), dU;
  VecX dx0, dv0;
  backward(sys, r, U, cost, dU, dx0, dv0);
  EXPECT_TRUE(dx0.allFinite() && dv0.allFinite());
  for (const auto& d : dU) ASSERT_TRUE(d.allFinite());
  EXPECT_GT(dU[0].norm(), 1e-8);
}

TEST(FlockStability, LongHorizonStaysFiniteWithCheckpointedGradient) {
  const int steps = 3000;
  FlockSystem sys(flock_spec(40), 1.0 / 30, steps, 5);
  VecX x0, v0;
  sys.initial_state(x0, v0);
  const VecX zero = VecX::Zero(sys.dof());
  Rollout r;
  RolloutOptions options;
  options.checkpoint_every = 100;
  LastStateCost cost(steps);
  options.keep_for = &cost;
  const StepControl u = [&](int) -> const VecX& { return zero; };
  ASSERT_TRUE(simulate(sys, x0, v0, steps, u, r, options)) << r.diverged_at;
  EXPECT_TRUE(test::all_finite(r));
  EXPECT_LT(r.stored_bytes(), std::size_t(2 * 40) * sys.dof() * sizeof(double) * 2);
  VecX dx0, dv0;
  bool finite = true;
  backward(sys, r, u, cost, [&](int, const VecX& g) { finite = finite && g.allFinite(); }, dx0, dv0);
  EXPECT_TRUE(finite);
  EXPECT_TRUE(dx0.allFinite() && dv0.allFinite());
}

// 400 agents within a 1.5 m square: each feels the velocity matching of all the others (radius 3 m), so
// the explicit step's update of its own velocity, 1 - h (c sum w + drag)/m, falls below -1 at 30 steps a
// second. The step refuses that state and says why; ten times smaller steps take it.
TEST(FlockStability, APackedCrowdWhoseMatchingTheStepOvershootsIsRefusedWithTheReason) {
  const int p = 400;
  std::mt19937_64 rng(4);
  const VecX x = random_planar(p, 0.75, rng), v = random_planar(p, 1.0, rng), u = VecX::Zero(3 * p);
  for (const int per_second : {30, 300}) {
    FlockSystem sys(flock_spec(p, 20), 1.0 / per_second, 10, 5);
    VecX x1, v1;
    const bool taken = sys.step(0, x, v, u, x1, v1);
    const std::string why = sys.divergence_reason();
    if (per_second == 30) {
      EXPECT_FALSE(taken);
      EXPECT_NE(why.find("matching"), std::string::npos) << why;
      EXPECT_NE(why.find("time.substeps"), std::string::npos) << why;
    } else {
      EXPECT_TRUE(taken) << why;
      EXPECT_TRUE(why.empty()) << why;
    }
  }
}

// The same packed crowd with its own-velocity damping taken implicitly: the step is taken at 30 steps a second
// and, held packed for a second, relative velocities decay instead of growing (the explicit step, allowed to
// go on, multiplies them by |1 - a| > 1 each step). Matching and drag alone act, so nothing but damping
// changes the velocities.
TEST(FlockStability, ImplicitDampingTakesThePackedCrowdAndItsRelativeVelocitiesDecay) {
  const int p = 400;
  std::mt19937_64 rng(4);
  const VecX x = random_planar(p, 0.75, rng), v = random_planar(p, 1.0, rng), u = VecX::Zero(3 * p);
  FlockSpec spec = flock_spec(p, 20);
  spec.avoidance.strength = spec.centering.strength = spec.wander.strength = 0;
  spec.implicit_damping = true;
  FlockSystem sys(spec, 1.0 / 30, 30, 5);
  auto spread = [&](const VecX& vv) {  // largest deviation from the mean velocity (m/s)
    Vec3 mean = Vec3::Zero();
    for (int i = 0; i < p; ++i) mean += seg(vv, i) / p;
    double worst = 0;
    for (int i = 0; i < p; ++i) worst = std::max(worst, (seg(vv, i) - mean).norm());
    return worst;
  };
  VecX v_now = v, x1, v1;
  for (int n = 0; n < 30; ++n) {  // positions held, so the packing and its damping stay as they are
    ASSERT_TRUE(sys.step(n, x, v_now, u, x1, v1)) << sys.divergence_reason();
    EXPECT_TRUE(sys.divergence_reason().empty());
    v_now = v1;
  }
  EXPECT_LT(spread(v_now), 0.1 * spread(v));
}

}  // namespace
}  // namespace kf

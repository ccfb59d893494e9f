// The memory estimate made before a run, and checkpointing switched on by a budget.
#include <gtest/gtest.h>

#include <vector>

#include "adjoint/memory_estimate.h"
#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/flock/flock_system.h"
#include "sim/make_system.h"

namespace kf {
namespace {

MemoryEstimate example() {
  MemoryEstimate e;
  e.base = 1000;
  e.per_state = 480;
  e.per_record = 900;
  e.steps = 180;
  e.extra_kept = 2;
  return e;
}

TEST(MemoryEstimate, StoredCountsEveryStateAndEntry) {
  const MemoryEstimate e = example();
  EXPECT_EQ(e.bytes(0), 1000u + 181u * 480u + 180u * 900u);
}

TEST(MemoryEstimate, SpacingIsZeroWhenEverythingFits) {
  const MemoryEstimate e = example();
  bool fits = false;
  EXPECT_EQ(checkpoint_spacing_for(e, e.bytes(0), fits), 0);
  EXPECT_TRUE(fits);
}

TEST(MemoryEstimate, SpacingNeedsLeastMemoryOfAllSpacings) {
  const MemoryEstimate e = example();
  bool fits = true;
  const int k = checkpoint_spacing_for(e, e.bytes(0) - 1, fits);
  ASSERT_GT(k, 1);
  for (int j = 1; j <= e.steps; ++j) ASSERT_LE(e.bytes(k), e.bytes(j)) << "spacing " << j << " needs less than " << k;
  EXPECT_LT(e.bytes(k), e.bytes(0) / 3);
  EXPECT_TRUE(fits);
  checkpoint_spacing_for(e, e.bytes(k) - 1, fits);
  EXPECT_FALSE(fits) << "a budget below the least estimate cannot be met";
}

TEST(MemoryEstimate, MachineHasMemory) {
  EXPECT_GT(physical_memory_bytes(), std::size_t(1) << 28);
  EXPECT_EQ(default_memory_budget(), physical_memory_bytes() / 2);
}

TEST(MemoryEstimate, ResidentMemoryGrowsWithWhatIsHeld) {
  const std::size_t before = resident_bytes();
  EXPECT_GT(before, std::size_t(1) << 20) << "the process's own code is resident";
  EXPECT_LT(before, physical_memory_bytes());
  std::vector<char> held(std::size_t(64) << 20, 1);  // touched, so resident
  EXPECT_GE(resident_bytes(), before + (std::size_t(60) << 20));
  EXPECT_EQ(held[12345], 1);
}

Scene flock_scene(int agents) {
  const std::string text = R"({
    "time": {"fps": 15, "substeps": 2, "frames": 20},
    "flock": {"agents": )" + std::to_string(agents) + R"(, "spawn": {"radius": 9, "velocity": [0, 0, 1.5]}},
    "objectives": [
      {"type": "shape", "frame": 10, "polygon": [[-4, 2], [4, 2], [4, 10], [-4, 10]]},
      {"type": "center_of_mass", "frame": 20, "target": [1, 0, 5]}
    ],
    "controls": {"kind": "per_frame", "alpha": 0.01}
  })";
  return parse_scene(text, "memory_flock.json");
}

// The flock's tape holds only its centering quantities, so its records stay at the estimate made before
// the run however the controls bunch the agents (the adjoint searches for neighbours again).
TEST(MemoryEstimate, FlockRecordEstimateBoundsTheTape) {
  const Scene scene = flock_scene(300);
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  const std::size_t before = sys->record_bytes_estimate();
  EXPECT_EQ(before, 300u * 3 * sizeof(double));
  for (double push : {0.5, 20.0}) {
    VecX z = problem.initial_guess() + push * VecX::Random(problem.size()), g(problem.size());
    problem.evaluate(z, &g);
    ASSERT_FALSE(problem.last_diverged());
    std::size_t most = 0;
    for (const auto& rec : problem.rollout().tape) {
      const auto& r = static_cast<const FlockRecord&>(*rec);
      most = std::max(most, r.bytes());
    }
    EXPECT_EQ(most, before) << "controls of " << push << " N";
  }
  EXPECT_EQ(sys->record_bytes_estimate(), before) << "estimate after the runs";
}

// A budget below the stored estimate checkpoints the rollout, and the gradient keeps its bits.
TEST(MemoryEstimate, BudgetSwitchesCheckpointingOnWithTheSameGradient) {
  const Scene scene = flock_scene(200);
  auto run = [&](std::size_t budget, int& every, std::size_t& bytes) {
    auto sys = make_system(scene);
    Problem problem(scene, scene.time, *sys);
    problem.set_memory_budget(budget);
    VecX z = problem.initial_guess() + 0.3 * VecX::Ones(problem.size()), g(problem.size());
    problem.evaluate(z, &g);
    EXPECT_FALSE(problem.last_diverged());
    every = problem.rollout().every;
    bytes = problem.rollout().stored_bytes();
    return g;
  };
  int every_all = -1, every_tight = -1;
  std::size_t bytes_all = 0, bytes_tight = 0;
  const VecX g_all = run(0, every_all, bytes_all);
  const VecX g_tight = run(200 * 6 * 8 * 10, every_tight, bytes_tight);  // room for about 10 states
  EXPECT_EQ(every_all, 0);
  EXPECT_GT(every_tight, 1);
  EXPECT_LT(bytes_tight, bytes_all * 6 / 10);
  ASSERT_GT(g_all.norm(), 1e-6);
  EXPECT_EQ((g_all - g_tight).cwiseAbs().maxCoeff(), 0.0);
}

TEST(MemoryEstimate, SceneKeyIsReadAndRangeChecked) {
  Scene s = flock_scene(10);
  EXPECT_EQ(s.optimizer.max_memory, 0.0);
  const std::string text = R"({"time": {"frames": 2}, "flock": {"agents": 3, "spawn": {"radius": 3}},
    "objectives": [{"type": "center_of_mass", "frame": 2, "target": [0, 0, 1]}],
    "optimizer": {"max_memory": 1.5}})";
  EXPECT_EQ(parse_scene(text, "m.json").optimizer.max_memory, 1.5);
  std::string bad = text;
  bad.replace(bad.find("1.5"), 3, "-1");
  EXPECT_ANY_THROW(parse_scene(bad, "m.json"));
}

}  // namespace
}  // namespace kf

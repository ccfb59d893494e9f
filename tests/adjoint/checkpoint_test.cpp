// Checkpointed adjoints: the same gradient as the stored trajectory, bit for bit, in far less memory.
#include <gtest/gtest.h>

#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/make_system.h"

namespace kf {
namespace {

// An 8 x 8 cloth pinned at its top corners with per-frame controls and keyframes off the checkpoints.
Scene cloth_scene(int frames, int substeps, const std::string& controls = "per_frame") {
  const std::string text = R"({
    "time": {"fps": 30, "substeps": )" + std::to_string(substeps) + R"(, "frames": )" + std::to_string(frames) + R"(},
    "cloth": {"nx": 8, "ny": 8, "pins": "top_corners", "cg_tolerance": 1e-6,
              "colliders": [{"type": "sphere", "center": [0.5, -0.4, 0.2], "radius": 0.3}]},
    "objectives": [
      {"type": "position", "frame": )" + std::to_string(frames / 3) + R"(, "particles": [3], "targets": [[0.4, 0.6, 0.3]]},
      {"type": "center_of_mass", "frame": )" + std::to_string(frames) + R"(, "target": [0.6, 0.2, 0.4], "weight": 2}
    ],
    "controls": {"kind": ")" + controls + R"(", "alpha": 0.01}
  })";
  return parse_scene(text, "checkpoint_cloth.json");
}

Scene flock_scene(int frames) {
  const std::string text = R"({
    "time": {"fps": 30, "substeps": 2, "frames": )" + std::to_string(frames) + R"(},
    "flock": {"agents": 40, "spawn": {"radius": 5, "velocity": [0, 0, 1]}},
    "objectives": [
      {"type": "center_of_mass", "frame": 7, "target": [1, 0, 2]},
      {"type": "shape", "frame": )" + std::to_string(frames) + R"(, "polygon": [[-2, 3], [2, 3], [2, 7], [-2, 7]]}
    ],
    "controls": {"kind": "per_step", "alpha": 0.01}
  })";
  return parse_scene(text, "checkpoint_flock.json");
}

struct Evaluated {
  double phi;
  VecX grad;
  std::size_t bytes;
};

Evaluated evaluate(const Scene& scene, int every, const VecX& z_offset) {
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  problem.set_checkpoint_every(every);
  const VecX z = problem.initial_guess() + z_offset;
  VecX g(problem.size());
  Evaluated e;
  e.phi = problem.evaluate(z, &g);
  EXPECT_FALSE(problem.last_diverged());
  e.grad = g;
  e.bytes = problem.rollout().stored_bytes();
  return e;
}

VecX offset(const Scene& scene, double scale) {
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  return scale * VecX::Random(problem.size());
}

TEST(Checkpointing, LongClothRunSameGradientInAQuarterOfTheMemory) {
  const Scene scene = cloth_scene(100, 40);  // 4,000 steps
  ASSERT_EQ(scene.time.steps(), 4000);
  const VecX dz = offset(scene, 0.05);
  const Evaluated stored = evaluate(scene, 0, dz);
  const Evaluated ckpt = evaluate(scene, 50, dz);
  ASSERT_GT(stored.grad.norm(), 1e-6);
  EXPECT_EQ(stored.phi, ckpt.phi);
  EXPECT_EQ((stored.grad - ckpt.grad).cwiseAbs().maxCoeff(), 0.0) << "gradients differ";
  EXPECT_LE(4 * ckpt.bytes, stored.bytes) << "stored " << stored.bytes << " B, checkpointed " << ckpt.bytes << " B";
  RecordProperty("stored_bytes", std::to_string(stored.bytes));
  RecordProperty("checkpointed_bytes", std::to_string(ckpt.bytes));
}

class CheckpointSpacing : public ::testing::TestWithParam<int> {};

// Spacings that divide the steps, do not, are 1, and exceed the run; keyframes fall between checkpoints.
TEST_P(CheckpointSpacing, ClothGradientIsBitIdentical) {
  const Scene scene = cloth_scene(12, 5, "per_step");  // 60 steps
  const VecX dz = offset(scene, 0.02);
  const Evaluated stored = evaluate(scene, 0, dz), ckpt = evaluate(scene, GetParam(), dz);
  ASSERT_GT(stored.grad.norm(), 1e-6);
  EXPECT_EQ(stored.phi, ckpt.phi);
  EXPECT_EQ((stored.grad - ckpt.grad).cwiseAbs().maxCoeff(), 0.0);
}

TEST_P(CheckpointSpacing, FlockGradientIsBitIdentical) {
  const Scene scene = flock_scene(30);  // 60 steps
  const VecX dz = offset(scene, 0.2);
  const Evaluated stored = evaluate(scene, 0, dz), ckpt = evaluate(scene, GetParam(), dz);
  ASSERT_GT(stored.grad.norm(), 1e-6);
  EXPECT_EQ(stored.phi, ckpt.phi);
  EXPECT_EQ((stored.grad - ckpt.grad).cwiseAbs().maxCoeff(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Spacings, CheckpointSpacing, ::testing::Values(1, 7, 10, 59, 60, 500));

TEST(Checkpointing, InitialVelocityControlGradientIsBitIdentical) {
  const Scene scene = cloth_scene(12, 5, "initial_velocity");
  const VecX dz = offset(scene, 0.1);
  const Evaluated stored = evaluate(scene, 0, dz), ckpt = evaluate(scene, 8, dz);
  ASSERT_GT(stored.grad.norm(), 1e-6);
  EXPECT_EQ((stored.grad - ckpt.grad).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Checkpointing, RepeatedEvaluationsAgreeWhateverCameBefore) {
  // The step context restored at each checkpoint must not depend on earlier evaluations.
  const Scene scene = cloth_scene(12, 5, "per_step");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  problem.set_checkpoint_every(9);
  const VecX z = problem.initial_guess() + 0.02 * VecX::Random(problem.size());
  VecX g1(problem.size()), g2(problem.size()), g_other(problem.size());
  const double phi1 = problem.evaluate(z, &g1);
  problem.evaluate(z + VecX::Constant(z.size(), 0.1), &g_other);
  const double phi2 = problem.evaluate(z, &g2);
  ASSERT_GT(g1.norm(), 1e-6);
  EXPECT_EQ(phi1, phi2);
  EXPECT_EQ((g1 - g2).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Checkpointing, SceneKeyIsReadAndRangeChecked) {
  std::string text = R"({"cloth": {"nx": 3, "ny": 3}, "optimizer": {"checkpoint_every": 25}})";
  EXPECT_EQ(parse_scene(text, "a.json").optimizer.checkpoint_every, 25);
  text = R"({"cloth": {"nx": 3, "ny": 3}, "optimizer": {"checkpoint_every": -1}})";
  EXPECT_THROW(parse_scene(text, "a.json"), std::exception);
}

}  // namespace
}  // namespace kf

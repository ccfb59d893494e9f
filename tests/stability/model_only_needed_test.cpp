// "Model only what a scene needs": a flock scene builds no cloth machinery, a cloth without colliders
// builds no collision structures, and neither pays for them per step.
#include <gtest/gtest.h>

#include "scene/scene.h"
#include "sim/cloth/cloth_system.h"
#include "sim/flock/flock_system.h"
#include "sim/make_system.h"

namespace kf {
namespace {

TEST(ModelOnlyWhatIsNeeded, FlockSceneBuildsAFlockSystemOnly) {
  const Scene scene = parse_scene(R"({"flock": {"agents": 20, "spawn": {"radius": 5}}})", "f.json");
  auto sys = make_system(scene);
  EXPECT_NE(dynamic_cast<FlockSystem*>(sys.get()), nullptr);
  EXPECT_EQ(dynamic_cast<ClothSystem*>(sys.get()), nullptr);
  EXPECT_EQ(sys->describe().find("cloth"), std::string::npos) << sys->describe();
}

TEST(ModelOnlyWhatIsNeeded, ClothWithoutCollidersBuildsNoCollisionStructures) {
  const Scene plain = parse_scene(R"({"cloth": {"nx": 6, "ny": 6}})", "c.json");
  auto sys = make_system(plain);
  auto* cloth = dynamic_cast<ClothSystem*>(sys.get());
  ASSERT_NE(cloth, nullptr);
  EXPECT_EQ(cloth->colliders(), 0);
  const Scene with = parse_scene(
      R"({"cloth": {"nx": 6, "ny": 6, "colliders": [{"type": "ground"}, {"type": "sphere", "center": [0, -1, 0]}]}})",
      "c.json");
  auto sys2 = make_system(with);
  EXPECT_EQ(dynamic_cast<ClothSystem*>(sys2.get())->colliders(), 2);
}

}  // namespace
}  // namespace kf

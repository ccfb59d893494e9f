#include <gtest/gtest.h>

#include "core/error.h"
#include "scene/scene.h"
#include "sim/flock/flock_spawn.h"
#include "sim/make_system.h"

namespace kf {
namespace {

std::string error_of(const std::string& flock_block) {
  try {
    parse_scene(R"({"flock": )" + flock_block + "}", "s.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(FlockSpec, DefaultsWhenEmpty) {
  const Scene s = parse_scene(R"({"seed": 7, "flock": {}})", "s.json");
  ASSERT_TRUE(s.flock);
  EXPECT_EQ(s.flock->agents, 200);
  EXPECT_EQ(s.flock->mass, 1.0);
  EXPECT_EQ(s.flock->avoidance.radius, 1.5);
  EXPECT_EQ(s.flock->wander.correlation_steps, 30);
  auto sys = make_system(s);
  EXPECT_EQ(sys->particles(), 200);
  EXPECT_TRUE(sys->planar());
  EXPECT_EQ(sys->describe(),
            "flock: 200 agents, mass 1 kg, forces: avoidance, matching, centering, wander, drag; grid neighbour "
            "search, radius 5 m");
}

TEST(FlockSpec, ReadsEveryKey) {
  const Scene s = parse_scene(R"({"flock": {"agents": 50, "mass": 2,
      "spawn": {"center": [1, 0, -2], "radius": 6, "velocity": [0.5, 0, 0]},
      "avoidance": {"strength": 3, "radius": 1}, "matching": {"strength": 0, "radius": 2},
      "centering": {"strength": 0.5, "radius": 4}, "wander": {"strength": 0.1, "correlation_steps": 10},
      "drag": {"strength": 0.3}, "step": "implicit_damping"}})",
                              "s.json");
  const FlockSpec& f = *s.flock;
  EXPECT_EQ(f.agents, 50);
  EXPECT_EQ(f.mass, 2);
  EXPECT_EQ(f.spawn.center, Vec3(1, 0, -2));
  EXPECT_EQ(f.spawn.velocity, Vec3(0.5, 0, 0));
  EXPECT_EQ(f.avoidance.strength, 3);
  EXPECT_EQ(f.matching.strength, 0);
  EXPECT_EQ(f.centering.radius, 4);
  EXPECT_EQ(f.wander.correlation_steps, 10);
  EXPECT_EQ(f.drag.strength, 0.3);
  EXPECT_TRUE(f.implicit_damping);
  EXPECT_EQ(make_system(s)->describe(),
            "flock: 50 agents, mass 2 kg, forces: avoidance, centering, wander, drag; grid neighbour search, radius 4 m; "
            "own-velocity damping implicit");
  EXPECT_FALSE(parse_scene(R"({"flock": {}})", "s.json").flock->implicit_damping);
}

TEST(FlockSpec, RejectsMalformedBlocks) {
  EXPECT_EQ(error_of(R"({"agents": 0})"), "s.json: /flock/agents: expected an integer in [1, 1000000], got 0");
  EXPECT_EQ(error_of(R"({"mass": -1})"), "s.json: /flock/mass: expected a number in [1e-06, 1e+06], got -1");
  EXPECT_EQ(error_of(R"({"avoidance": {"radius": -1}})"),
            "s.json: /flock/avoidance/radius: expected a number in [0.001, 10000], got -1");
  EXPECT_EQ(error_of(R"({"centering": {"strength": "high"}})"),
            "s.json: /flock/centering/strength: expected a number, got string \"high\"");
  EXPECT_EQ(error_of(R"({"wander": {"strenght": 1}})"),
            "s.json: /flock/wander/strenght: unknown key (check its spelling; see README 'Scene files')");
  EXPECT_EQ(error_of(R"({"wander": {"correlation_steps": 2.5}})"),
            "s.json: /flock/wander/correlation_steps: expected an integer, got number 2.5");
  EXPECT_EQ(error_of(R"({"drag": 3})"), "s.json: /flock/drag: expected an object, got number 3");
  const std::string step = error_of(R"({"step": "implicit"})");
  EXPECT_EQ(step.rfind("s.json: /flock/step: ", 0), 0u) << step;
  EXPECT_NE(step.find("implicit_damping"), std::string::npos) << step;
  EXPECT_EQ(error_of(R"({"speed": 3})"),
            "s.json: /flock/speed: unknown key (check its spelling; see README 'Scene files')");
  EXPECT_EQ(error_of(R"({"spawn": {"center": [0, 1, 0]}})"),
            "s.json: /flock/spawn/center: expected [x, 0, z] (flocks live on the ground plane y = 0), got y = 1");
  const std::string small = error_of(R"({"agents": 200, "spawn": {"radius": 1}})");
  EXPECT_EQ(small.rfind("s.json: /flock/spawn/radius: too small for 200 agents at least 0.9 m apart", 0), 0u) << small;
}

TEST(FlockSpawn, FillsTheDiscWithoutCloseAgents) {
  for (int agents : {1, 2, 20, 200, 1000}) {
    FlockSpec spec;
    spec.agents = agents;
    spec.spawn.center = Vec3(3, 0, -1);
    spec.spawn.radius = std::max(1.0, std::sqrt(agents / M_PI) * 1.0);  // ~1 m apart
    const VecX x = spawn_positions(spec, 11);
    ASSERT_EQ(x.size(), 3 * agents);
    double closest = 1e9;
    for (int i = 0; i < agents; ++i) {
      EXPECT_EQ(x[3 * i + 1], 0.0);
      EXPECT_LE((seg(x, i) - spec.spawn.center).norm(), spec.spawn.radius + 1e-12) << "agent " << i;
      for (int j = 0; j < i; ++j) closest = std::min(closest, (seg(x, i) - seg(x, j)).norm());
    }
    if (agents > 1) {
      EXPECT_GE(closest, spec.min_spawn_distance() - 1e-12) << agents << " agents";
    }
    EXPECT_EQ(spawn_positions(spec, 11), x);
    if (agents > 1) {
      EXPECT_NE(spawn_positions(spec, 12), x) << "seed must change the jitter";
    }
  }
}

TEST(FlockSpawn, RefusesADiscTooSmallForItsAgents) {
  FlockSpec spec;
  spec.agents = 200;
  spec.spawn.radius = 1;  // holds a handful at the minimum distance
  EXPECT_THROW(spawn_positions(spec, 11), std::invalid_argument);
}

}  // namespace
}  // namespace kf

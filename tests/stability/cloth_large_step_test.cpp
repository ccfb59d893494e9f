// Stiff sheets thrown at one step per 24- or 30-fps frame: no divergence, no energy gained.
//
// A linearised backward Euler step made these gain energy (a pin's neighbour or a spinning sheet moves
// across springs whose transverse stiffness is 0 at rest length; a step entering a collider ends deep in
// it) and, 300 times stiffer than the default, fail ("diverged at step ...") within half a second. The
// cloth splits the steps that gain energy (ClothSpec::max_halvings); with splitting off the same cases fail.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

#include "scene/scene.h"
#include "adjoint/rollout.h"
#include "sim/cloth/cloth_system.h"
#include "stability_util.h"

namespace kf {
namespace {

struct ThrowCase {
  double stiffer;    // stretch as a multiple of the default
  int fps;           // one step per frame
  bool pinned;       // top corners pinned (a swing) or free (thrown up with a spin)
  std::string body;  // "none", "ground", "sphere"
};

std::string name_of(const ThrowCase& c) {
  return "x" + std::to_string(int(c.stiffer)) + "_" + std::to_string(c.fps) + "fps_" + (c.pinned ? "pinned" : "free") +
         "_" + c.body;
}

void PrintTo(const ThrowCase& c, std::ostream* os) { *os << name_of(c); }

ClothSpec spec_of(const ThrowCase& c, int max_halvings = 8) {
  ClothSpec spec = *parse_scene(R"({"cloth": {"nx": 16, "ny": 16}})", "throw.json").cloth;
  spec.stretch *= c.stiffer;
  spec.max_halvings = max_halvings;
  if (c.pinned) {
    spec.pins = named_pin_set("top_corners", spec.nx, spec.ny);
    spec.origin = Vec3(-0.5, 0.5, 0);  // hangs from y = 1.5 in the x-y plane
  } else {
    spec.origin = Vec3(-0.5, 1.0, -0.5);
    spec.v_axis = Vec3(0, 0.6, 0.8);  // tilted, 1.0 .. 1.6 m high
  }
  if (c.body == "ground") {
    GroundShape ground;
    ground.point = Vec3(0, c.pinned ? 0.45 : 0.0, 0);  // the swing's lowest row grazes it
    spec.colliders.push_back({ground});
  }
  if (c.body == "sphere") {
    SphereShape sphere;
    sphere.center = c.pinned ? Vec3(0, 0.3, 0.45) : Vec3(0.3, 0.35, 0.6);  // in the swing's path / under the fall
    sphere.radius = 0.35;
    spec.colliders.push_back({sphere});
  }
  return spec;
}

class ClothLargeStep : public ::testing::TestWithParam<ThrowCase> {};

struct ThrowOutcome {
  int failed_at = -1;             // step whose solve failed, or -1
  double e0 = 0, kinetic0 = 0;    // initial total and kinetic energy, J
  double highest = 0;             // highest total energy met, J
  double travelled = 0, worst_strain = 0;
  int substeps = 0, split_steps = 0;
  double cg_iterations = 0;
  std::vector<std::pair<std::string, double>> stats;  // the system's run_stats after the throw
  Rollout r;
};

// The throw: the swing at 3 m/s across the sheet; the free sheet 3 m/s up with a 9.4 rad/s spin.
ThrowOutcome run_throw(const ThrowCase& c, int max_halvings) {
  const ClothSpec spec = spec_of(c, max_halvings);
  ClothSystem sys(spec, 1.0 / c.fps);
  VecX x, v;
  sys.initial_state(x, v);
  Vec3 centre = Vec3::Zero();
  for (int i = 0; i < sys.particles(); ++i) centre += seg(x, i) / sys.particles();
  const Vec3 throw_v = c.pinned ? Vec3(0, 0, 3) : Vec3(0.5, 3, 0.5), spin = c.pinned ? Vec3(0, 0, 0) : Vec3(4, 3, 8);
  for (int i = 0; i < sys.particles(); ++i)
    if (!sys.pinned(i)) seg(v, i) = throw_v + spin.cross(Vec3(seg(x, i) - centre));
  ThrowOutcome o;
  o.r.x.assign(1, x);
  o.r.v.assign(1, v);
  const VecX u = VecX::Zero(sys.dof());
  o.e0 = sys.energy(0, x, v).total();
  o.kinetic0 = sys.energy(0, x, v).kinetic;
  o.highest = o.e0;
  for (int n = 0; n < 72; ++n) {
    VecX x1(sys.dof()), v1(sys.dof());
    if (!sys.step(n, o.r.x[n], o.r.v[n], u, x1, v1)) {
      o.failed_at = n;
      return o;
    }
    o.substeps += sys.last_substeps();
    o.split_steps += sys.last_substeps() > 1;
    o.cg_iterations += sys.last_cg_iterations();
    o.highest = std::max(o.highest, sys.energy(n + 1, x1, v1).total());
    for (int i = 0; i < sys.particles(); ++i) o.travelled = std::max(o.travelled, (seg(x1, i) - seg(x, i)).norm());
    for (const BucklingSpring& s : sys.springs())
      if (s.k == spec.stretch)
        o.worst_strain = std::max(o.worst_strain, (seg(x1, s.b) - seg(x1, s.a)).norm() / s.rest - 1);
    o.r.x.push_back(std::move(x1));
    o.r.v.push_back(std::move(v1));
  }
  o.stats = sys.run_stats();
  return o;
}

TEST_P(ClothLargeStep, RunsSeventyTwoFramesWithoutGainingEnergy) {
  const ThrowCase c = GetParam();
  const ThrowOutcome o = run_throw(c, 8);
  ASSERT_EQ(o.failed_at, -1) << name_of(c) << ": diverged at step " << o.failed_at;
  std::printf("%s: %d substeps for 72 steps, highest energy %.4g J from %.4g J\n", name_of(c).c_str(), o.substeps,
              o.highest, o.e0);
  ASSERT_GT(o.kinetic0, 1.0);
  EXPECT_TRUE(test::all_finite(o.r));
  // The total with the springs' and colliders' energy, which a made-up step shows first, stays below its start.
  EXPECT_LE(o.highest, o.e0 + 1e-3 * o.kinetic0) << name_of(c) << ": energy rose to " << o.highest << " J from "
                                                 << o.e0 << " J";
  // Stiff sheets barely stretch, and the throw did move the sheet.
  EXPECT_LT(o.worst_strain, 0.1) << name_of(c);
  EXPECT_GT(o.travelled, 0.3) << name_of(c);
  // Splitting does not run away to its limit (256 substeps a step): 300 times stiffer sheets take up to
  // about 40 a step, the most when swinging from pinned corners (their strains are so small that the
  // definite Jacobian's transverse stiffness, faded in over strains up to kTransverseRamp, is nearly off);
  // tests/results/stability/large_step.csv has the counts.
  EXPECT_LE(o.substeps, 48 * 72) << name_of(c);
  // The run report counts the same splits and iterations as the steps did.
  ASSERT_EQ(o.stats.size(), 2u);
  EXPECT_EQ(o.stats[0].first, "split_steps");
  EXPECT_EQ(o.stats[0].second, o.split_steps);
  EXPECT_EQ(o.split_steps > 0, o.substeps > 72);
  EXPECT_EQ(o.stats[1].first, "pcg_iterations_per_step");
  EXPECT_DOUBLE_EQ(o.stats[1].second, o.cg_iterations / 72);
}

std::vector<ThrowCase> all_cases() {
  std::vector<ThrowCase> cases;
  for (double stiffer : {10.0, 300.0})
    for (int fps : {24, 30})
      for (bool pinned : {true, false})
        for (const char* body : {"none", "ground", "sphere"}) cases.push_back({stiffer, fps, pinned, body});
  return cases;
}

INSTANTIATE_TEST_SUITE_P(StiffThrownSheets, ClothLargeStep, ::testing::ValuesIn(all_cases()),
                         [](const auto& info) { return name_of(info.param); });

TEST(ClothLargeStep, WithoutSplittingTheHardestThrowsGainEnergyOrFail) {
  // The check the test above makes can fail: the same throws with plain linearised steps.
  int bad = 0;
  for (const ThrowCase& c : {ThrowCase{300, 24, false, "sphere"}, ThrowCase{300, 24, false, "ground"}}) {
    const ThrowOutcome o = run_throw(c, 0);
    bad += o.failed_at >= 0 || o.highest > o.e0 + 1e-3 * o.kinetic0;
    std::printf("%s without splitting: failed at %d, highest energy %.4g J from %.4g J\n", name_of(c).c_str(),
                o.failed_at, o.highest, o.e0);
  }
  EXPECT_EQ(bad, 2);
}

TEST(ClothLargeStep, DefaultSheetAtSixtyHertzIsNeverSplit) {
  // The check costs nothing where the plain step was already fine.
  ClothSpec spec = *parse_scene(R"({"cloth": {"nx": 12, "ny": 12, "pins": "top_corners", "velocity": [0, 0, 1]}})",
                                "plain.json").cloth;
  ClothSystem sys(spec, 1.0 / 60);
  VecX x, v, x1(3 * spec.particles()), v1(3 * spec.particles());
  sys.initial_state(x, v);
  const VecX u = VecX::Zero(3 * spec.particles());
  for (int n = 0; n < 120; ++n) {
    ASSERT_TRUE(sys.step(n, x, v, u, x1, v1));
    ASSERT_EQ(sys.last_substeps(), 1) << "step " << n << " was split";
    x = x1;
    v = v1;
  }
}

}  // namespace
}  // namespace kf

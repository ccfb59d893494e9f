// The throw search ends at a throw that meets the keyframes (opt/throw_search.h): a candidate of its own
// sequence that carries the sheet through them ends it there; without the scene it flies every throw.
#include <gtest/gtest.h>

#include <sstream>

#include "opt/problem.h"
#include "opt/throw_search.h"
#include "scene/scene.h"
#include "sim/make_system.h"

namespace kf {
namespace {

const std::string kCloth = R"("time": {"fps": 30, "substeps": 2, "frames": 16}, "cloth": {"nx": 6, "ny": 6,
    "width": 0.4, "height": 0.4, "origin": [-0.2, 1.0, -0.2], "u_axis": [1, 0, 0], "v_axis": [0, 0, 1],
    "velocity": [1, 2, 0], "mass": 0.1, "air_drag": 0.1, "cg_tolerance": 1e-12})";
const std::string kRigid = R"(, "controls": {"kind": "initial_rigid_velocity"})";

// Particles 0, 14 and 35 at frame 16 where the throw z carries them.
std::string keyframes_of(const VecX& z) {
  const Scene thrower = parse_scene("{" + kCloth + kRigid + R"(, "objectives": [{"type": "center_of_mass",
      "frame": 8, "target": [0, 1, 0]}]})", "thrower.json");
  auto sys = make_system(thrower);
  Problem fly(thrower, thrower.time, *sys);
  fly.evaluate(z, nullptr);
  const VecX& x = fly.rollout().x[32];
  std::ostringstream os;
  os.precision(17);
  os << R"(, "objectives": [{"type": "position", "frame": 16, "particles": [0, 14, 35], "targets": [)";
  for (int i : {0, 14, 35}) os << (i ? "," : "") << "[" << x[3 * i] << "," << x[3 * i + 1] << "," << x[3 * i + 2] << "]";
  os << "]}]";
  return os.str();
}

TEST(ThrowSearchStop, EndsAtAThrowThatMeetsTheKeyframes) {
  // The search's first throw: Δv_d = (2 / prime_d − 1) × the box's half-width (primes 2, 3, 5), no spin; the
  // box is ±max(1, half the mean initial speed) = ±√5 / 2 m/s.
  const double half = 0.5 * std::sqrt(5.0);
  VecX first = VecX::Zero(6);
  first << 0, (2.0 / 3 - 1) * half, (2.0 / 5 - 1) * half, 0, 0, 0;
  const Scene scene = parse_scene("{" + kCloth + kRigid + keyframes_of(first) + "}", "keyframes.json");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  const ThrowSearch found = search_throws(problem, 64, {}, nullptr, &scene);
  EXPECT_TRUE(found.met);
  EXPECT_EQ(found.simulated, 1);
  EXPECT_LT((found.z - first).norm(), 1e-12);
  const ThrowSearch all = search_throws(problem, 64);
  EXPECT_FALSE(all.met);
  EXPECT_EQ(all.simulated, 64);
  EXPECT_EQ(all.z, found.z);  // the same throw is the best of all
}

// A scene whose keyframes the search cannot judge (a velocity keyframe places no particles) flies every throw.
TEST(ThrowSearchStop, FliesEveryThrowWhenAKeyframePlacesNoParticles) {
  const Scene scene = parse_scene("{" + kCloth + kRigid + R"(, "objectives": [{"type": "center_of_mass", "frame": 8,
      "target": [0.2, 1.3, -0.3]}, {"type": "velocity", "frame": 16, "targets": [[0, 0, 0]]}]})", "velocity.json");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  const ThrowSearch found = search_throws(problem, 16, {}, nullptr, &scene);
  EXPECT_FALSE(found.met);
  EXPECT_EQ(found.simulated, 16);
}

}  // namespace
}  // namespace kf

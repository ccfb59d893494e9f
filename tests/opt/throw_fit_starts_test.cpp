// The rigid fit after the throw search starts from the search's best few throws, not only its best
// (opt/throw_search.h): a landing throw's best throw flown often lies in another basin than the keyframes'.
// The search keeps its kFitStarts best throws in order; a small sheet's fit starts from each of them, a large
// flight's from the best alone.
#include <gtest/gtest.h>

#include <sstream>

#include "opt/problem.h"
#include "opt/throw_search.h"
#include "scene/scene.h"
#include "sim/make_system.h"

namespace kf {
namespace {

// An n x n sheet thrown for 16 frames of two steps (n = 20: 12800 particle-steps, a large flight).
std::string cloth(int n) {
  return R"("time": {"fps": 30, "substeps": 2, "frames": 16}, "cloth": {"nx": )" + std::to_string(n) +
         R"(, "ny": )" + std::to_string(n) +
         R"(, "width": 0.4, "height": 0.4, "origin": [-0.2, 1.0, -0.2], "u_axis": [1, 0, 0], "v_axis": [0, 0, 1],
         "velocity": [1, 2, 0], "mass": 0.1, "air_drag": 0.1})";
}

// Three particles at frame 16 where the throw (Δv, ω) = (0.7, -0.4, 0.5, 2, 0, -1) carries them, the last one's
// target moved by `off` (m) along x, which no rigid throw follows exactly.
Scene thrown(int n, double off = 0) {
  const std::string rigid = R"(, "controls": {"kind": "initial_rigid_velocity"})";
  const Scene thrower = parse_scene("{" + cloth(n) + rigid + R"(, "objectives": [{"type": "center_of_mass",
      "frame": 8, "target": [0, 1, 0]}]})", "thrower.json");
  auto sys = make_system(thrower);
  Problem fly(thrower, thrower.time, *sys);
  VecX z(6);
  z << 0.7, -0.4, 0.5, 2, 0, -1;
  fly.evaluate(z, nullptr);
  const VecX& x = fly.rollout().x[32];
  const int last = n * n - 1;
  std::ostringstream os;
  os.precision(17);
  os << R"(, "objectives": [{"type": "position", "frame": 16, "particles": [0, )" << n << ", " << last
     << R"(], "targets": [)";
  for (int i : {0, n, last})
    os << (i ? "," : "") << "[" << x[3 * i] + (i == last ? off : 0.0) << "," << x[3 * i + 1] << "," << x[3 * i + 2] << "]";
  os << "]}]";
  return parse_scene("{" + cloth(n) + rigid + os.str() + "}", "keyframes.json");
}

TEST(ThrowFitStarts, TheSearchKeepsItsBestFewThrowsInOrder) {
  const Scene scene = thrown(6);
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  const ThrowSearch found = search_throws(problem, 16);
  ASSERT_EQ(found.best_throws.size(), size_t(kFitStarts));
  EXPECT_EQ(found.best_throws.front(), found.z);  // a thrown search's best beats the scene's own throw here
  double previous = 0;
  for (const VecX& z : found.best_throws) {
    const double phi = problem.evaluate(z, nullptr);
    EXPECT_GE(phi, previous);
    previous = phi;
  }
  // Fewer throws than kFitStarts: each of them.
  EXPECT_EQ(search_throws(problem, 2).best_throws.size(), 2u);
}

TEST(ThrowFitStarts, ASmallSheetsFitStartsFromEachOfTheBestThrowsALargeFlightsFromTheBest) {
  // Eight throws: the first fit and each later one get a quarter of them (two flights, no Jacobian), so none
  // reaches and every start is tried.
  for (int n : {6, 20}) {
    SCOPED_TRACE(n);
    const Scene scene = thrown(n);
    auto sys = make_system(scene);
    Problem problem(scene, scene.time, *sys);
    const ThrowSearch found = search_and_fit_throws(problem, scene, 8, 1000);
    ASSERT_TRUE(found.rigid.has_value());
    EXPECT_FALSE(found.rigid->reached());
    const int first_fit = 1;  // two flights end the first fit within its first start
    if (n == 6) EXPECT_EQ(found.rigid->starts, first_fit + kFitStarts);
    else EXPECT_LE(found.rigid->starts, first_fit + 1);  // the best, when it is not the fitted or the scene's throw
    EXPECT_LE(found.simulated, 1000);
  }
}

// A fit that ends within half of every tolerance without reaching its 1 % (a target 6 mm off the rigid motion:
// the fit converges a few millimetres away) is met as the search's early end would meet it: no search follows.
TEST(ThrowFitStarts, AFitWithinHalfOfEveryToleranceRunsNoSearch) {
  const Scene scene = thrown(6, 0.006);
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  const ThrowSearch found = search_and_fit_throws(problem, scene, 512, 100000);
  ASSERT_TRUE(found.rigid.has_value());
  EXPECT_FALSE(found.rigid->reached());
  EXPECT_LE(found.rigid->worst_miss, 0.5);
  EXPECT_GT(found.rigid->worst_miss, 0.01);
  EXPECT_LT(found.simulated, 200) << "the search ran after a fit within half of every tolerance";
}

}  // namespace
}  // namespace kf

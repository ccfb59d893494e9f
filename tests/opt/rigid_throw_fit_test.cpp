// Levenberg–Marquardt on the six rigid throw variables (opt/rigid_throw_fit.h): a known rigid throw of a
// free sheet is recovered from its keyframes, and reduced generated throws are met by the fit alone.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "bench/bench_reachable.h"
#include "opt/problem.h"
#include "opt/rigid_throw_fit.h"
#include "opt/throw_fit.h"
#include "opt/throw_search.h"
#include "scene/scene.h"
#include "sim/make_system.h"

namespace kf {
namespace {

const std::string kCloth = R"("time": {"fps": 30, "substeps": 2, "frames": 16}, "cloth": {"nx": 6, "ny": 6,
    "width": 0.4, "height": 0.4, "origin": [-0.2, 1.0, -0.2], "u_axis": [1, 0, 0], "v_axis": [0, 0, 1],
    "velocity": [1, 2, 0], "mass": 0.1, "air_drag": 0.1, "cg_tolerance": 1e-12})";

// Position keyframes of every particle where the sheet thrown with `thrown` is at `frames`.
std::string flown_keyframes(const VecX& thrown, std::initializer_list<int> frames, const std::string& kind) {
  const Scene thrower = parse_scene("{" + kCloth + R"(, "objectives": [{"type": "center_of_mass", "frame": 8,
      "target": [0, 1, 0]}], "controls": {"kind": "initial_rigid_velocity"}})", "throw.json");
  auto sys = make_system(thrower);
  Problem fly(thrower, thrower.time, *sys);
  fly.evaluate(thrown, nullptr);
  std::ostringstream os;
  os.precision(17);
  os << "[";
  bool first = true;
  for (int frame : frames) {
    const VecX& x = fly.rollout().x[size_t(frame) * 2];
    os << (first ? "" : ",") << R"({"type": "position", "frame": )" << frame << R"(, "targets": [)";
    first = false;
    for (int i = 0; i < 36; ++i) os << (i ? "," : "") << "[" << x[3 * i] << "," << x[3 * i + 1] << "," << x[3 * i + 2] << "]";
    os << "]}";
  }
  os << "]";
  return "{" + kCloth + R"(, "objectives": )" + os.str() + R"(, "controls": {"kind": ")" + kind + R"(", "alpha": 0}})";
}

TEST(RigidThrowFit, RecoversAKnownRigidThrowOfAFreeSheet) {
  VecX thrown(6);
  thrown << 0.5, 1.0, -0.3, 4.0, 0.5, -2.0;  // m/s and rad/s: turned about 0.8 rad by frame 16
  const Scene scene = parse_scene(flown_keyframes(thrown, {6, 11, 16}, "initial_rigid_velocity"), "keyframes.json");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  RigidFitOptions o;
  o.reach_share = 0;  // to convergence
  const RigidThrowFit fit = fit_rigid_throw(problem, scene, {VecX::Zero(6)}, o);
  ASSERT_EQ(fit.z.size(), 6);
  EXPECT_LT((fit.z - thrown).norm(), 1e-6) << fit.z.transpose();
  ASSERT_EQ(fit.starts, 1);
  EXPECT_GT(fit.start_costs[0], 1e6 * fit.cost);
  EXPECT_LE(fit.simulated, o.max_simulations);
  // Each iteration is a Jacobian (twelve flights) and a step: a zero-residual problem takes a handful.
  EXPECT_LT(fit.simulated, 13 * 12) << fit.simulated;
}

TEST(RigidThrowFit, StopsAtItsBudgetAndOnASignal) {
  VecX thrown(6);
  thrown << 0.5, 1.0, -0.3, 9.0, 0.5, -2.0;
  const Scene scene = parse_scene(flown_keyframes(thrown, {16}, "initial_rigid_velocity"), "keyframes.json");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  RigidFitOptions o;
  o.max_simulations = 7;
  RigidThrowFit fit = fit_rigid_throw(problem, scene, {VecX::Zero(6), VecX::Ones(6)}, o);
  EXPECT_EQ(fit.simulated, 7);
  ASSERT_EQ(fit.stops.size(), 1u);
  EXPECT_EQ(fit.stops[0], RigidFitStop::kBudget);
  std::atomic<bool> stop{true};
  o.max_simulations = 100;
  o.stop = &stop;
  fit = fit_rigid_throw(problem, scene, {VecX::Zero(6)}, o);
  EXPECT_EQ(fit.simulated, 0);
  EXPECT_EQ(fit.starts, 0);
}

TEST(RigidThrowFit, RefusesControlsThatAreNotARigidThrow) {
  VecX thrown = VecX::Zero(6);
  const Scene scene = parse_scene(flown_keyframes(thrown, {16}, "initial_velocity"), "keyframes.json");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  EXPECT_THROW(fit_rigid_throw(problem, scene, {VecX::Zero(6)}, {}), std::logic_error);
}

// The generated throw scenes as the rigid stage sees them: initial_rigid_velocity controls.
Scene rigid_scene(const ReachableScene& r) {
  Scene scene = parse_scene(r.scene.dump(), r.name + ".json");
  scene.controls.kind = ControlKind::kInitialRigidVelocity;
  return scene;
}

VecX truth(const ReachableScene& r) {
  VecX z(6);
  z << r.variant.dv, r.variant.omega;
  return z;
}

// Reduced generated throws (8 x 8, 15 frames; two or three keyframes, with friction; over a torus): the fit
// from the scene's own throw meets every keyframe in a few Jacobians, where the search simulates 516 throws.
// (Reduced throw-0 and throw-2, which land on a collider before their keyframe, are not met from there.)
TEST(RigidThrowFit, ReducedGeneratedThrowsAreMetFromTheScenesOwnThrow) {
  for (int index : {1, 3, 4}) {
    const ReachableScene r = generate_reachable("throw", 52, index, true, ".");
    SCOPED_TRACE(r.name);
    const Scene scene = rigid_scene(r);
    auto sys = make_system(scene);
    Problem problem(scene, scene.time, *sys);
    RigidFitOptions o;
    const RigidThrowFit fit = fit_rigid_throw(problem, scene, {VecX::Zero(6)}, o);
    ASSERT_EQ(fit.z.size(), 6);
    EXPECT_TRUE(fit.reached()) << describe(fit) << "; cost " << fit.start_costs[0] << " -> " << fit.cost
                               << "; the variant's " << truth(r).transpose() << " found " << fit.z.transpose();
    EXPECT_LT(fit.worst_miss, 0.01);
    EXPECT_LT(fit.simulated, 60);
    EXPECT_LT((fit.z - truth(r)).norm(), 1e-3 * truth(r).norm());
  }
}

// Not a check: what the throw search and the fit find on the full generated throws, against the variant's
// own (Δv, ω). KEYFRAME_THROWS="0 2 4" picks the scenes; KEYFRAME_WELL_CONDITIONED=1 draws them as
// --reachable-well-conditioned does.
TEST(RigidThrowFit, DISABLED_DiagnoseGeneratedThrows) {
  const char* env = std::getenv("KEYFRAME_THROWS");
  std::istringstream list(env ? env : "0 2 3 4 5 7 9 14 17 18 19 20 21");
  for (int index; list >> index;) {
    const ReachableScene r = generate_reachable("throw", 52, index, std::getenv("KEYFRAME_REDUCED") != nullptr, ".",
                                                std::getenv("KEYFRAME_WELL_CONDITIONED") != nullptr);
    const Scene scene = rigid_scene(r);
    auto sys = make_system(scene);
    Problem problem(scene, scene.time, *sys);
    const VecX z_true = truth(r);
    const double phi0 = problem.evaluate(VecX::Zero(6), nullptr);
    const double phi_true = problem.evaluate(z_true, nullptr);
    const auto t0 = std::chrono::steady_clock::now();
    const int count = std::min(automatic_throw_count(scene.cloth->particles(), scene.time.steps()),
                               2 * scene.optimizer.max_evaluations);
    const ThrowSearch s = search_throws(problem, count, refine_fitted_throw(problem, scene, 3));
    const double search_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::cout << r.name << " p=" << scene.cloth->particles() << " steps=" << scene.time.steps()
              << " colliders=" << scene.cloth->colliders.size() << " phi(scene)=" << phi0 << " phi(truth)=" << phi_true
              << " truth=" << z_true.transpose() << "\n  search " << s.simulated << " throws " << search_s
              << " s: phi=" << s.phi << " z=" << s.z.transpose() << " |z-truth|=" << (s.z - z_true).norm()
              << " box " << s.speed << " m/s " << s.spin << " rad/s\n";
    for (const auto& [name, start] : {std::pair<const char*, VecX>{"scene", VecX::Zero(6)}, {"search", s.z}, {"truth+10%", VecX(z_true * 1.1)}, {"truth+1%", VecX(z_true * 1.01)}}) {
      const auto t1 = std::chrono::steady_clock::now();
      RigidFitOptions o;
      o.max_simulations = 400;
      const RigidThrowFit fit = fit_rigid_throw(problem, scene, {start}, o);
      const double fit_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
      std::cout << "  LM from " << name << ": " << describe(fit) << " " << fit.simulated << " "
                << fit_s << " s cost " << fit.start_costs.back() << " -> " << fit.cost << " worst miss "
                << fit.worst_miss << " tol, phi " << problem.evaluate(fit.z, nullptr)
                << " |z-truth|=" << (fit.z - z_true).norm() << " z=" << fit.z.transpose() << "\n";
    }
  }
}

}  // namespace
}  // namespace kf

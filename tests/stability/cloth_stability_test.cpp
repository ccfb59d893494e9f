// Hard cloth cases: very stiff at a large step, draped over a sphere, degenerate springs, long horizons.
#include <gtest/gtest.h>

#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/cloth/cloth_system.h"
#include "sim/make_system.h"
#include "stability_util.h"

namespace kf {
namespace {

ClothSpec spec_from(const std::string& cloth) { return *parse_scene(R"({"cloth": )" + cloth + "}", "c.json").cloth; }

std::vector<VecX> no_controls(int steps, int dof) { return std::vector<VecX>(steps, VecX::Zero(dof)); }

TEST(ClothStability, HundredTimesStifferAtOneThirtiethSecond) {
  const ClothSpec d;
  ClothSpec spec = spec_from(R"({"nx": 16, "ny": 16, "pins": "top_corners"})");
  spec.stretch = 100 * d.stretch;
  spec.velocity = Vec3(0, 0, 2);  // a swing, not only a sag
  ClothSystem sys(spec, 1.0 / 30);
  VecX x0, v0;
  sys.initial_state(x0, v0);
  Rollout r;
  ASSERT_TRUE(simulate(sys, x0, v0, no_controls(90, sys.dof()), r)) << "diverged at step " << r.diverged_at;
  EXPECT_TRUE(test::all_finite(r));
  EXPECT_TRUE(test::energy_bounded(sys, r, 9.81, 1e-9));
  // Very stiff structural springs barely stretch: no edge longer than 10 % over rest.
  for (const auto& s : sys.springs())
    if (s.k == spec.stretch) EXPECT_LT((seg(r.x.back(), s.b) - seg(r.x.back(), s.a)).norm(), 1.1 * s.rest);
  // Its adjoint stays finite too.
  VecX xh = VecX::Ones(sys.dof()), vh = VecX::Ones(sys.dof()), xo, vo, uo;
  sys.step_adjoint(89, r.x[89], r.v[89], VecX::Zero(sys.dof()), xh, vh, xo, vo, uo);
  EXPECT_TRUE(xo.allFinite() && vo.allFinite() && uo.allFinite());
}

TEST(ClothStability, DroppedOntoASphereFoldsOverItWithoutBlowingUp) {
  // A horizontal sheet falls 0.3 m onto a sphere smaller than itself; its skirt folds down around it.
  ClothSpec spec = spec_from(R"({"nx": 14, "ny": 14, "origin": [-0.5, 0.3, -0.5], "v_axis": [0, 0, 1],
      "colliders": [{"type": "sphere", "center": [0, 0, 0], "radius": 0.25, "thickness": 0.02, "stiffness": 2e4}]})");
  ClothSystem sys(spec, 1.0 / 120);
  VecX x0, v0;
  sys.initial_state(x0, v0);
  Rollout r;
  ASSERT_TRUE(simulate(sys, x0, v0, no_controls(240, sys.dof()), r)) << "diverged at step " << r.diverged_at;
  EXPECT_TRUE(test::all_finite(r));
  EXPECT_TRUE(test::energy_bounded(sys, r, 9.81, 1e-9));
  double lowest_edge = 1e9, deepest = 1e9;
  for (int i = 0; i < sys.particles(); ++i) {
    const Vec3 p = seg(r.x.back(), i);
    deepest = std::min(deepest, p.norm());
    if (i < spec.nx) lowest_edge = std::min(lowest_edge, p.y());
  }
  EXPECT_GT(deepest, 0.8 * 0.25) << "cloth went deep into the sphere";
  EXPECT_LT(lowest_edge, 0.0) << "the edge did not fold down over the sphere";
}

TEST(ClothStability, CoincidentAndNearlyCoincidentParticles) {
  // Springs squeezed to zero length and to 1e-12 of their rest length: forces and adjoint stay finite.
  ClothSystem sys(spec_from(R"({"nx": 5, "ny": 5, "pins": "top_corners"})"), 1.0 / 60);
  VecX x0, v0;
  sys.initial_state(x0, v0);
  seg(x0, 6) = seg(x0, 7);                              // zero-length structural spring
  seg(x0, 12) = seg(x0, 13) + Vec3(1e-13, 0, 0);        // nearly degenerate
  seg(x0, 18) = seg(x0, 24 - 5) + Vec3(0, 0, 1e-300);   // denormal-close
  Rollout r;
  ASSERT_TRUE(simulate(sys, x0, v0, no_controls(120, sys.dof()), r)) << "diverged at step " << r.diverged_at;
  EXPECT_TRUE(test::all_finite(r));
  // The squeezed springs push the particles apart again.
  EXPECT_GT((seg(r.x.back(), 6) - seg(r.x.back(), 7)).norm(), 0.05);
  VecX xh = VecX::Ones(sys.dof()), vh = VecX::Ones(sys.dof()), xo, vo, uo;
  sys.step_adjoint(0, r.x[0], r.v[0], VecX::Zero(sys.dof()), xh, vh, xo, vo, uo);
  EXPECT_TRUE(xo.allFinite() && vo.allFinite() && uo.allFinite());
}

// Scene files cannot reach this (height >= 1e-4); built directly, it exercises the L = 0 limit of the
// spring and damping terms, where d/|d| does not exist.
TEST(ClothStability, ZeroRestLengthSpringsStayFinite) {
  // A sheet of zero height (built directly: scene files forbid it) has zero-rest-length springs.
  ClothSpec spec = spec_from(R"({"nx": 4, "ny": 3, "pins": "top_corners"})");
  spec.height = 0;
  ClothSystem sys(spec, 1.0 / 60);
  VecX x0, v0;
  sys.initial_state(x0, v0);
  Rollout r;
  ASSERT_TRUE(simulate(sys, x0, v0, no_controls(30, sys.dof()), r)) << "diverged at step " << r.diverged_at;
  EXPECT_TRUE(test::all_finite(r));
  EXPECT_TRUE(test::energy_bounded(sys, r, 9.81, 1e-9));
  // The zero-rest-length springs pull the coincident rows together: they stay within a few mm.
  double longest = 0;
  for (const auto& s : sys.springs())
    if (s.rest == 0) longest = std::max(longest, (seg(r.x.back(), s.b) - seg(r.x.back(), s.a)).norm());
  EXPECT_LT(longest, 0.01);
  // The adjoint at the first step, where those springs have exactly zero length, stays finite.
  VecX xh = VecX::Ones(sys.dof()), vh = VecX::Ones(sys.dof()), xo, vo, uo;
  sys.step_adjoint(0, r.x[0], r.v[0], VecX::Zero(sys.dof()), xh, vh, xo, vo, uo);
  EXPECT_TRUE(xo.allFinite() && vo.allFinite() && uo.allFinite());
  EXPECT_GT(uo.norm(), 0);
}

TEST(ClothStability, LongHorizonComesToRestAndKeepsItsGradient) {
  // 2,400 steps (10 s at 1/240 s): a hanging sheet settles; the checkpointed gradient stays finite.
  const std::string text = R"({
    "time": {"fps": 30, "substeps": 8, "frames": 300},
    "cloth": {"nx": 8, "ny": 8, "pins": "top_corners", "velocity": [0, 0, 1]},
    "objectives": [{"type": "center_of_mass", "frame": 300, "target": [0.5, 0.2, 0.3]}],
    "controls": {"kind": "per_frame", "alpha": 0.001},
    "optimizer": {"checkpoint_every": 60}
  })";
  const Scene scene = parse_scene(text, "long.json");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  problem.evaluate(problem.initial_guess(), nullptr);
  const Rollout& r = problem.rollout();
  ASSERT_EQ(r.steps(), 2400);
  EXPECT_TRUE(test::all_finite(r));
  EXPECT_TRUE(test::energy_bounded(*sys, r, 9.81, 1e-9));
  auto kinetic = [&](const VecX& v) {
    double ke = 0;
    for (int i = 0; i < sys->particles(); ++i) ke += 0.5 * sys->masses()[i] * seg(v, i).squaredNorm();
    return ke;
  };
  double peak = 0;
  for (const auto& v : r.v) peak = std::max(peak, kinetic(v));
  EXPECT_LT(kinetic(r.v.back()), 0.1 * peak) << "still swinging after 10 s";
  VecX g(problem.size());
  const double phi = problem.evaluate(problem.initial_guess(), &g);
  EXPECT_FALSE(problem.last_diverged());
  EXPECT_TRUE(std::isfinite(phi));
  EXPECT_TRUE(g.allFinite());
  EXPECT_GT(g.norm(), 1e-8);
}

TEST(ClothStability, HugeTrialControlsGiveALargeFiniteValue) {
  const std::string text = R"({
    "time": {"fps": 30, "substeps": 2, "frames": 10},
    "cloth": {"nx": 6, "ny": 6, "pins": "top_corners"},
    "objectives": [{"type": "center_of_mass", "frame": 10, "target": [0.5, 0.3, 0.3]}],
    "controls": {"kind": "per_frame", "alpha": 0.001}
  })";
  const Scene scene = parse_scene(text, "huge.json");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  VecX g(problem.size());
  const double phi0 = problem.evaluate(problem.initial_guess(), &g);
  ASSERT_FALSE(problem.last_diverged());
  for (double scale : {1e30, 1e100, 1e150, 1e300}) {
    const double phi = problem.evaluate(VecX::Constant(problem.size(), scale), &g);
    EXPECT_TRUE(std::isfinite(phi)) << scale;
    EXPECT_TRUE(g.allFinite()) << scale;
    if (problem.last_diverged()) EXPECT_GT(phi, phi0) << scale;
  }
}

}  // namespace
}  // namespace kf

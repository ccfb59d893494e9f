// The exact cloth adjoint against finite differences of whole simulations (keyframe gradcheck's check):
// small scenes with each collider, pins, compression, per-step and initial-velocity controls, at steps
// from 1/30 to 1/960 s and at zero and perturbed controls. The adjoint must agree to 1e-6 on every
// checked sample, and at most a few samples may be kinks (differences that never converge).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "opt/gradcheck.h"
#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/make_system.h"
#include "gradient_test_helpers.h"

namespace kf {
namespace {

struct Case {
  const char* name;
  const char* cloth;       // the cloth block's extra keys
  const char* controls;    // the controls block
  const char* objectives;  // the objectives array
  double eps;              // finite-difference step (initial velocities are O(1) m/s: a larger one)
};

// 6x6 sheets, 0.5 m, 0.1 s of animation at 30 fps (3 frames).
const Case kCases[] = {
    {"sphere_pinned", R"("origin": [-0.25, 0.12, -0.25], "v_axis": [0, 0, 1], "pins": "top_corners",
       "colliders": [{"type": "sphere", "center": [0, 0, 0], "radius": 0.1, "thickness": 0.03, "stiffness": 3000}])",
     R"({"kind": "per_step", "alpha": 1e-4})",
     R"([{"type": "center_of_mass", "frame": 3, "weight": 100, "target": [0.05, 0.2, 0]}])", 1e-4},
    {"ground_falling", R"("origin": [-0.25, 0.02, -0.25], "v_axis": [0, 0.2, 0.98], "velocity": [0.3, -0.6, 0],
       "colliders": [{"type": "ground", "center": [0, 0, 0], "axis": [0, 1, 0], "thickness": 0.03, "stiffness": 3000}])",
     R"({"kind": "per_frame", "alpha": 1e-4})",
     R"([{"type": "center_of_mass", "frame": 3, "weight": 100, "target": [0.1, 0.1, 0]}])", 1e-4},
    {"torus_throw", R"("origin": [-0.45, 0.95, -0.1], "width": 0.2, "height": 0.2, "v_axis": [0, 0, 1],
       "velocity": [3, 1, 0], "colliders": [{"type": "torus", "center": [0, 1.05, 0], "axis": [1, 0, 0],
       "radius": 0.15, "tube_radius": 0.03, "thickness": 0.03, "stiffness": 3000}])",
     R"({"kind": "initial_velocity", "alpha": 1e-4})",
     R"([{"type": "center_of_mass", "frame": 3, "weight": 100, "target": [0, 1.2, 0]}])", 1e-3},
    {"torus_rigid_throw", R"("origin": [-0.45, 0.95, -0.1], "width": 0.2, "height": 0.2, "v_axis": [0, 0, 1],
       "velocity": [3, 1, 0], "colliders": [{"type": "torus", "center": [0, 1.05, 0], "axis": [1, 0, 0],
       "radius": 0.15, "tube_radius": 0.03, "thickness": 0.03, "stiffness": 3000}])",
     R"({"kind": "initial_rigid_velocity", "alpha": 1e-4})",
     R"([{"type": "position", "frame": 3, "weight": 100, "particles": [0, 35], "targets": [[-0.1, 1.1, -0.1], [0.1, 1.2, 0.1]]}])",
     1e-3},
    {"torus_lattice_throw", R"("origin": [-0.45, 0.95, -0.1], "width": 0.2, "height": 0.2, "v_axis": [0, 0, 1],
       "velocity": [3, 1, 0], "colliders": [{"type": "torus", "center": [0, 1.05, 0], "axis": [1, 0, 0],
       "radius": 0.15, "tube_radius": 0.03, "thickness": 0.03, "stiffness": 3000}])",
     R"({"kind": "initial_lattice_velocity", "alpha": 1e-4})",
     R"([{"type": "position", "frame": 3, "weight": 100, "particles": [0, 35], "targets": [[-0.1, 1.1, -0.1], [0.1, 1.2, 0.1]]}])",
     1e-3},
    {"compressed_arch", R"("origin": [-0.25, 0, -0.25], "v_axis": [0, 0, 1], "gravity": [0, 0, 0])",
     R"({"kind": "per_frame", "alpha": 1e-5})",
     R"([{"type": "arch", "frame": 3, "weight": 100, "axis_point": [0, -0.2, 0], "axis": [0, 0, 1], "radius": 0.3}])",
     1e-4},
    // Control forces added after the solve (cloth.control_integration): their adjoint skips the solve.
    {"explicit_compressed_arch", R"("origin": [-0.25, 0, -0.25], "v_axis": [0, 0, 1], "gravity": [0, 0, 0],
       "control_integration": "explicit")",
     R"({"kind": "per_frame", "alpha": 1e-5})",
     R"([{"type": "arch", "frame": 3, "weight": 100, "axis_point": [0, -0.2, 0], "axis": [0, 0, 1], "radius": 0.3}])",
     1e-4},
    {"explicit_sphere_pinned", R"("origin": [-0.25, 0.12, -0.25], "v_axis": [0, 0, 1], "pins": "top_corners",
       "control_integration": "explicit",
       "colliders": [{"type": "sphere", "center": [0, 0, 0], "radius": 0.1, "thickness": 0.03, "stiffness": 3000}])",
     R"({"kind": "per_step", "alpha": 1e-4})",
     R"([{"type": "center_of_mass", "frame": 3, "weight": 100, "target": [0.05, 0.2, 0]}])", 1e-4},
    // The theta step (cloth.theta) below backward Euler's 1, with the narrow transverse ramp it needs: pins,
    // contact, compression and both control integrations.
    {"theta_sphere_pinned", R"("origin": [-0.25, 0.12, -0.25], "v_axis": [0, 0, 1], "pins": "top_corners",
       "theta": 0.6, "transverse_ramp": 0.002,
       "colliders": [{"type": "sphere", "center": [0, 0, 0], "radius": 0.1, "thickness": 0.03, "stiffness": 3000}])",
     R"({"kind": "per_step", "alpha": 1e-4})",
     R"([{"type": "center_of_mass", "frame": 3, "weight": 100, "target": [0.05, 0.2, 0]}])", 1e-4},
    {"theta_ground_falling", R"("origin": [-0.25, 0.02, -0.25], "v_axis": [0, 0.2, 0.98], "velocity": [0.3, -0.6, 0],
       "theta": 0.5, "transverse_ramp": 0.002,
       "colliders": [{"type": "ground", "center": [0, 0, 0], "axis": [0, 1, 0], "thickness": 0.03, "stiffness": 3000}])",
     R"({"kind": "per_frame", "alpha": 1e-4})",
     R"([{"type": "center_of_mass", "frame": 3, "weight": 100, "target": [0.1, 0.1, 0]}])", 1e-4},
    // Friction (off in the cases above: colliders are frictionless unless the scene says): a sheet landing
    // flat and sliding fast along the ground (slip >> friction_velocity), one set down slowly so it sticks
    // (slip << friction_velocity), a coefficient high enough that the sheet lying on a sphere holds, and the
    // sphere without friction.
    {"ground_sliding", R"("origin": [-0.25, 0.012, -0.25], "v_axis": [0, 0, 1], "velocity": [1.5, -0.05, 0.4],
       "colliders": [{"type": "ground", "thickness": 0.03, "stiffness": 3000, "friction": 0.6}])",
     R"({"kind": "per_frame", "alpha": 1e-4})",
     R"([{"type": "center_of_mass", "frame": 3, "weight": 100, "target": [0.2, 0.05, 0.1]}])", 1e-3},
    {"ground_sticking", R"("origin": [-0.25, 0.012, -0.25], "v_axis": [0, 0, 1], "velocity": [0.002, -0.01, 0.001],
       "colliders": [{"type": "ground", "thickness": 0.03, "stiffness": 3000, "friction": 0.8, "friction_velocity": 0.05}])",
     R"({"kind": "per_frame", "alpha": 1e-4})",
     R"([{"type": "center_of_mass", "frame": 3, "weight": 100, "target": [0.02, 0.05, 0.01]}])", 1e-4},
    {"sphere_draped_high_friction", R"("origin": [-0.25, 0.12, -0.25], "v_axis": [0, 0, 1], "imperfection": 5e-4,
       "colliders": [{"type": "sphere", "center": [0, 0, 0], "radius": 0.1, "thickness": 0.03, "stiffness": 3000, "friction": 1.5}])",
     R"({"kind": "per_frame", "alpha": 1e-4})",
     R"([{"type": "position", "frame": 3, "weight": 100, "particles": [0], "targets": [[-0.2, 0.0, -0.2]]}])", 1e-4},
    {"sphere_pinned_frictionless", R"("origin": [-0.25, 0.12, -0.25], "v_axis": [0, 0, 1], "pins": "top_corners",
       "colliders": [{"type": "sphere", "center": [0, 0, 0], "radius": 0.1, "thickness": 0.03, "stiffness": 3000, "friction": 0}])",
     R"({"kind": "per_step", "alpha": 1e-4})",
     R"([{"type": "center_of_mass", "frame": 3, "weight": 100, "target": [0.05, 0.2, 0]}])", 1e-4},
    // A sheet sliding with friction across a table (a box) and over its rounded edge, and one landing across
    // the edge of a panel (a rectangle), part of it falling past.
    {"box_edge_sliding", R"("origin": [-0.25, 0.012, -0.25], "v_axis": [0, 0, 1], "velocity": [1.5, -0.05, 0.4],
       "colliders": [{"type": "box", "center": [0.05, -0.1, 0], "size": [0.5, 0.2, 0.6], "radius": 0.04,
                      "thickness": 0.03, "stiffness": 3000, "friction": 0.6}])",
     R"({"kind": "per_frame", "alpha": 1e-4})",
     R"([{"type": "center_of_mass", "frame": 3, "weight": 100, "target": [0.2, 0.05, 0.1]}])", 1e-4},
    {"rectangle_edge_landing", R"("origin": [-0.25, 0.02, -0.25], "v_axis": [0, 0, 1], "velocity": [0.3, -0.6, 0],
       "colliders": [{"type": "rectangle", "center": [0.15, 0, 0], "width": 0.4, "height": 0.8, "thickness": 0.03,
                      "stiffness": 3000, "friction": 0.4}])",
     R"({"kind": "per_frame", "alpha": 1e-4})",
     R"([{"type": "center_of_mass", "frame": 3, "weight": 100, "target": [0.1, 0.1, 0]}])", 1e-4},
    {"theta_explicit_compressed_arch", R"("origin": [-0.25, 0, -0.25], "v_axis": [0, 0, 1], "gravity": [0, 0, 0],
       "theta": 0.55, "transverse_ramp": 0.002, "control_integration": "explicit")",
     R"({"kind": "per_frame", "alpha": 1e-5})",
     R"([{"type": "arch", "frame": 3, "weight": 100, "axis_point": [0, -0.2, 0], "axis": [0, 0, 1], "radius": 0.3}])",
     1e-4},
};

Scene scene_of(const Case& c, int substeps) {
  return parse_scene(std::string(R"({"time": {"fps": 30, "frames": 3, "substeps": )") + std::to_string(substeps) +
                         R"(}, "cloth": {"nx": 6, "ny": 6, "width": 0.5, "height": 0.5, "mass": 0.1,
                            "solver": "direct", )" +
                         c.cloth + R"(}, "controls": )" + c.controls + R"(, "objectives": )" + c.objectives + "}",
                     std::string(c.name) + ".json");
}

class ClothExactAdjoint : public ::testing::TestWithParam<const Case*> {};

TEST_P(ClothExactAdjoint, MatchesFiniteDifferencesAtEveryStepAndPerturbation) {
  const Case& c = *GetParam();
  for (int substeps : {1, 2, 8, 32}) {
    const Scene scene = scene_of(c, substeps);
    auto sys = make_system(scene);
    Problem problem(scene, scene.time, *sys);
    test::gradcheck_perturbed(problem, c.eps, {0.0, 0.01, 0.1}, [&](double perturb, const GradcheckResult& r) {
      std::printf("%s h = 1/%d, perturb %g: max_rel_error %.2e, fd_spread %.2e, %d checked, %d kinks\n", c.name,
                  30 * substeps, perturb, r.max_rel_error, r.fd_spread, r.checked, r.kinks);
      ASSERT_GT(r.grad_norm, 0) << c.name;
      EXPECT_GE(r.checked, std::min(14, problem.size())) << c.name << " h = 1/" << 30 * substeps;
      EXPECT_LE(r.max_rel_error, 1e-6) << c.name << " h = 1/" << 30 * substeps << " perturb " << perturb;
    });
  }
}

// Forces on the 3 x 3 lattice (a coarse stage before per-particle forces): the chain rule through the
// lattice, in contact (a pinned sheet on a sphere, a sheet sliding with friction) at perturbed controls.
TEST(ClothExactAdjointLattice, LatticeForcesMatchFiniteDifferencesInContact) {
  for (const Case& c : kCases) {
    const std::string name = c.name;
    if (name != "sphere_pinned_frictionless" && name != "ground_sliding") continue;
    for (int substeps : {1, 4}) {
      Scene scene = scene_of(c, substeps);
      scene.controls.kind = ControlKind::kPerFrameLattice;
      auto sys = make_system(scene);
      Problem problem(scene, scene.time, *sys);
      ASSERT_EQ(problem.size(), 3 * 9 * 3);
      test::gradcheck_perturbed(problem, c.eps, {0.0, 0.01, 0.1}, [&](double perturb, const GradcheckResult& r) {
        ASSERT_GT(r.grad_norm, 0) << name;
        EXPECT_GE(r.checked, 14) << name;
        EXPECT_LE(r.max_rel_error, 1e-6) << name << " h = 1/" << 30 * substeps << " perturb " << perturb;
      });
    }
  }
}

INSTANTIATE_TEST_SUITE_P(SmallScenes, ClothExactAdjoint, ::testing::ValuesIn([] {
                           std::vector<const Case*> v;
                           for (const Case& c : kCases) v.push_back(&c);
                           return v;
                         }()),
                         [](const auto& info) { return std::string(info.param->name); });

}  // namespace
}  // namespace kf

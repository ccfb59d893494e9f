// The "cloth" block of a scene file.
#include <gtest/gtest.h>

#include "core/error.h"
#include "scene/scene.h"
#include "sim/cloth/cloth_system.h"
#include "sim/make_system.h"

namespace kf {
namespace {

Scene scene_with(const std::string& cloth) { return parse_scene(R"({"cloth": )" + cloth + "}", "c.json"); }

std::string error_of(const std::string& cloth) {
  try {
    scene_with(cloth);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(ClothSpec, DefaultsAndGridLayout) {
  const Scene s = scene_with(R"({"nx": 4, "ny": 3, "width": 0.6, "height": 0.4, "origin": [1, 2, 3]})");
  ASSERT_TRUE(s.cloth);
  const ClothSpec& c = *s.cloth;
  EXPECT_EQ(c.particles(), 12);
  EXPECT_TRUE(c.pins.empty());
  EXPECT_TRUE(c.colliders.empty());
  ClothSystem sys(c, 1.0 / 60);
  EXPECT_EQ(sys.colliders(), 0);
  VecX x, v;
  sys.initial_state(x, v);
  EXPECT_TRUE(seg(x, c.index(3, 2)).isApprox(Vec3(1.6, 2.4, 3)));
  EXPECT_NEAR(sys.masses().sum(), c.mass, 1e-12);
  // 4x3 grid: 9 + 8 structural, 12 shear, 6 + 4 bending.
  EXPECT_EQ(sys.springs().size(), 39u);
  EXPECT_EQ(sys.damped_springs(), 29);
}

TEST(ClothSpec, MotionToleranceOnlyWhereTheSceneStatesNone) {
  ClothSpec unstated = *scene_with(R"({"nx": 4, "ny": 4})").cloth;
  EXPECT_EQ(unstated.cg_tolerance, 1e-8);  // gradients
  unstated.use_motion_tolerance();
  EXPECT_EQ(unstated.cg_tolerance, ClothSpec::kMotionTolerance);
  ClothSpec stated = *scene_with(R"({"nx": 4, "ny": 4, "cg_tolerance": 1e-10})").cloth;
  stated.use_motion_tolerance();
  EXPECT_EQ(stated.cg_tolerance, 1e-10);
}

TEST(ClothSpec, NamedAndListedPins) {
  EXPECT_EQ(scene_with(R"({"nx": 4, "ny": 3, "pins": "top_corners"})").cloth->pins, (std::vector<int>{8, 11}));
  EXPECT_EQ(scene_with(R"({"nx": 4, "ny": 3, "pins": "left_edge"})").cloth->pins, (std::vector<int>{0, 4, 8}));
  EXPECT_EQ(scene_with(R"({"nx": 4, "ny": 3, "pins": [5, 1, 5]})").cloth->pins, (std::vector<int>{1, 5}));
  EXPECT_NE(error_of(R"({"nx": 4, "ny": 3, "pins": [12]})").find("/cloth/pins"), std::string::npos);
  EXPECT_NE(error_of(R"({"pins": "top"})").find("/cloth/pins: expected one of"), std::string::npos);
}

TEST(ClothSpec, CollidersAndErrorsNameTheirPlace) {
  const Scene s = scene_with(
      R"({"colliders": [{"type": "ground"}, {"type": "torus", "center": [0, 1, 0], "radius": 0.2,
          "tube_radius": 0.02, "axis": [0, 0, 2]}]})");
  ASSERT_EQ(s.cloth->colliders.size(), 2u);
  EXPECT_EQ(std::get<TorusShape>(s.cloth->colliders[1].shape).axis, Vec3(0, 0, 1));
  EXPECT_STREQ(type_name(s.cloth->colliders[0]), "ground");
  EXPECT_EQ(make_system(s)->describe(), "cloth: 16x16 particles, 1378 springs, 0 pinned, 2 colliders, PCG (incomplete_cholesky, tolerance 1e-08), exact adjoint");
  EXPECT_EQ(scene_with(R"({"cg_preconditioner": "block_jacobi"})").cloth->cg_preconditioner, "block_jacobi");
  EXPECT_NE(error_of(R"({"cg_preconditioner": "ilu"})").find("/cloth/cg_preconditioner: expected one of"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"colliders": [{"type": "ground", "radius": 1}]})").find("/cloth/colliders/0/radius: unknown key"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"stiffnes": 1})").find("/cloth/stiffnes: unknown key"), std::string::npos);
  EXPECT_NE(error_of(R"({"damping": -1})").find("/cloth/damping"), std::string::npos);
  EXPECT_NE(error_of(R"({"u_axis": [1, 0, 0], "v_axis": [1, 1, 0]})").find("perpendicular"), std::string::npos);
  EXPECT_NE(error_of(R"({"colliders": [{"type": "torus", "radius": 0.1, "tube_radius": 0.2}]})").find("tube_radius"),
            std::string::npos);
}

}  // namespace
}  // namespace kf

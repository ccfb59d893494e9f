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
  // In the sheet's plane exactly where the grid puts it; across it, the default waviness (half a millimetre).
  EXPECT_DOUBLE_EQ(seg(x, c.index(3, 2)).x(), 1.6);
  EXPECT_DOUBLE_EQ(seg(x, c.index(3, 2)).y(), 2.4);
  EXPECT_NEAR(seg(x, c.index(3, 2)).z(), 3.0, 5e-4);
  EXPECT_EQ(c.imperfection, 5e-4);
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
  EXPECT_EQ(make_system(s)->describe(), "cloth: 16x16 particles, 1378 springs, 0 pinned, 2 colliders (ground, torus), PCG (incomplete_cholesky, tolerance 1e-08), exact adjoint");
  EXPECT_EQ(scene_with(R"({"cg_preconditioner": "block_jacobi"})").cloth->cg_preconditioner, CgPreconditioner::kBlockJacobi);
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

TEST(ClothSpec, FrictionPerColliderFrictionlessByDefault) {
  const Scene s = scene_with(
      R"({"nx": 4, "ny": 4,
          "colliders": [{"type": "ground"}, {"type": "sphere", "friction": 0.4}, {"type": "torus", "friction": 0.3},
                        {"type": "capsule", "friction": 0.6}, {"type": "sphere", "friction": 0, "friction_velocity": 0.05}]})");
  const auto& c = s.cloth->colliders;
  ASSERT_EQ(c.size(), 5u);
  EXPECT_EQ(c[0].friction, 0.0);
  EXPECT_EQ(c[1].friction, 0.4);
  EXPECT_EQ(c[2].friction, 0.3);
  EXPECT_EQ(c[3].friction, 0.6);
  EXPECT_EQ(c[4].friction, 0.0);
  EXPECT_EQ(c[4].friction_velocity, 0.05);
  EXPECT_EQ(c[0].friction_velocity, 0.01);
  // The colliders the system builds carry them.
  const auto cols = make_colliders(c, 0.5);
  EXPECT_EQ(cols[2]->friction_params().mu, 0.3);
  EXPECT_FALSE(cols[4]->friction_params().on());
  const std::string e = error_of(R"({"colliders": [{"type": "ground"}, {"type": "sphere", "friction": -0.1}]})");
  EXPECT_NE(e.find("c.json"), std::string::npos) << e;
  EXPECT_NE(e.find("/cloth/colliders/1/friction"), std::string::npos) << e;
  EXPECT_NE(error_of(R"({"colliders": [{"type": "ground", "friction_velocity": 0}]})").find("/cloth/colliders/0/friction_velocity"),
            std::string::npos);
}

TEST(ClothSpec, ImperfectionIsSeededSubMillimetreAndValidated) {
  const ClothSpec c = *scene_with(R"({"nx": 4, "ny": 4, "imperfection": 5e-4, "imperfection_seed": 3})").cloth;
  EXPECT_EQ(c.imperfection, 5e-4);
  EXPECT_EQ(c.imperfection_seed, 3);
  EXPECT_EQ(scene_with(R"({"nx": 4, "ny": 4})").cloth->imperfection, 5e-4);  // on by default
  EXPECT_EQ(scene_with(R"({"nx": 4, "ny": 4, "imperfection": 0})").cloth->imperfection, 0.0);
  const std::string e = error_of(R"({"imperfection": 0.5})");
  EXPECT_NE(e.find("c.json"), std::string::npos) << e;
  EXPECT_NE(e.find("/cloth/imperfection"), std::string::npos) << e;
  EXPECT_NE(error_of(R"({"imperfection": -1e-4})").find("/cloth/imperfection"), std::string::npos);
  EXPECT_NE(error_of(R"({"imperfection_seed": -1})").find("/cloth/imperfection_seed"), std::string::npos);
  // The imperfection moves particles off the plane only, by at most its amplitude, the same for one seed.
  ClothSystem flat(*scene_with(R"({"nx": 5, "ny": 4, "v_axis": [0, 0, 1], "imperfection": 0})").cloth, 1.0 / 30);
  const ClothSpec bumpy = *scene_with(R"({"nx": 5, "ny": 4, "v_axis": [0, 0, 1], "imperfection": 5e-4})").cloth;
  ClothSystem a(bumpy, 1.0 / 30), b(bumpy, 1.0 / 30);
  VecX x0, v0, xa, va, xb, vb;
  flat.initial_state(x0, v0);
  a.initial_state(xa, va);
  b.initial_state(xb, vb);
  EXPECT_EQ(xa, xb);
  double largest = 0;
  for (int i = 0; i < 20; ++i) {
    const Vec3 d = seg(xa, i) - seg(x0, i);
    EXPECT_EQ(d.x(), 0.0);
    EXPECT_EQ(d.z(), 0.0);
    EXPECT_LE(std::abs(d.y()), 5e-4);
    largest = std::max(largest, std::abs(d.y()));
  }
  EXPECT_GT(largest, 2e-4);
  // Another seed, other draws; the springs rest in the moved shape, so it starts at rest.
  ClothSystem other(*scene_with(R"({"nx": 5, "ny": 4, "v_axis": [0, 0, 1], "imperfection": 5e-4, "imperfection_seed": 2})").cloth,
                    1.0 / 30);
  VecX xo, vo;
  other.initial_state(xo, vo);
  EXPECT_NE(xo, xa);
  EXPECT_NEAR(a.state_energy(xa, va).elastic, 0.0, 1e-15);
  // Pinned particles stay where the grid puts them; the free ones move as they do unpinned.
  ClothSystem pinned(*scene_with(R"({"nx": 5, "ny": 4, "v_axis": [0, 0, 1], "imperfection": 5e-4, "pins": [0, 4]})").cloth,
                     1.0 / 30);
  VecX xp, vp;
  pinned.initial_state(xp, vp);
  for (int i = 0; i < 20; ++i) EXPECT_EQ(seg(xp, i), (i == 0 || i == 4 ? seg(x0, i) : seg(xa, i))) << i;
}

}  // namespace
}  // namespace kf

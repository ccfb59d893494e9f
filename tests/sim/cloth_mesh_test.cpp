// Cloth from a triangle mesh (cloth.mesh): its springs, masses and start, every force term and the whole
// step's exact adjoint against central differences on an irregular mesh with a hole and a notch, and a grid
// against the same grid read from an OBJ file.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>

#include "app/run_dir.h"
#include "core/error.h"
#include "opt/problem.h"
#include "scene/cloth_mesh.h"
#include "scene/cloth_mesh_spec.h"
#include "sim/cape/self_collider.h"
#include "sim/cloth/cloth_springs.h"
#include "sim/cloth/cloth_terms.h"
#include "sim/cloth/mesh_layout.h"
#include "sim/make_system.h"
#include "cloth_mesh_test_util.h"
#include "cloth_term_check.h"
#include "gradient_test_helpers.h"

namespace kf {
namespace {

// The irregular patch (35 vertices: the notch's corner vertex belongs to no face) as the term checks' sheet.
std::string irregular_cloth(const std::filesystem::path& dir, const std::string& extra = "") {
  const auto file = test::write_irregular_obj(dir, Vec3(0, 0.02, 0), 0.3);
  return R"({"mesh": {"file": ")" + file.string() + R"("}, "mass": 0.1, "damping": 0.3, "air_drag": 0.5)" + extra +
         "}";
}

TEST(ClothMesh, ReadsTheIrregularPatchWithItsHoleAndNotch) {
  test::MeshDir dir;
  const Scene s = parse_scene(R"({"cloth": )" + irregular_cloth(dir.path()) + "}", dir.path() / "s.json");
  ASSERT_TRUE(s.cloth->mesh);
  EXPECT_EQ(s.particles(), 35);
  const ClothMesh& m = *s.cloth->mesh;
  int tris = 0, quads = 0;
  for (const auto& f : m.faces) (f.size() == 3 ? tris : quads)++;
  EXPECT_EQ(tris, 2 * 8);  // the 8 kept cells with (i + j) % 3 == 0
  EXPECT_EQ(quads, 25 - 2 - 8);
  EXPECT_EQ(m.triangles().size(), size_t(3 * (tris + 2 * quads)));
}

TEST(ClothMesh, MassesByAreaSumToTheClothsMassAndFollowTheFaces) {
  test::MeshDir dir;
  ClothSpec spec = *parse_scene(R"({"cloth": )" + irregular_cloth(dir.path()) + "}", dir.path() / "s.json").cloth;
  const VecX m = mesh_masses(spec);
  EXPECT_NEAR(m.sum(), 0.1, 1e-15);
  EXPECT_GT(m.minCoeff(), 0);
  // A corner vertex has one face, an interior one four: a quarter of the mass or less.
  EXPECT_LT(m[0], 0.4 * m[7]);
  spec.mass_by_area = false;
  EXPECT_EQ(mesh_masses(spec), VecX::Constant(35, 0.1 / 35));
}

// A grid's springs come from its quads: the same pairs, stiffnesses and rest lengths in the same order.
TEST(ClothMesh, AGridWrittenAsQuadsGetsTheGridsSpringsInTheGridsOrder) {
  test::MeshDir dir;
  const std::string grid = R"({"nx": 7, "ny": 5, "width": 0.6, "height": 0.4, "origin": [-0.3, 0.5, 0.1],
                               "u_axis": [1, 0, 0], "v_axis": [0, 0.6, 0.8], "imperfection": 0})";
  const ClothSpec g = *parse_scene(R"({"cloth": )" + grid + "}", dir.path() / "g.json").cloth;
  const auto file = test::write_grid_obj(dir.path(), g);
  const ClothSpec m = *parse_scene(R"({"cloth": {"mesh": {"file": ")" + file.string() + R"("}, "imperfection": 0}})",
                                   dir.path() / "m.json").cloth;
  ASSERT_EQ(m.particles(), g.particles());
  const VecX x0 = mesh_rest_positions(m);
  const ClothSprings a = make_cloth_springs(g, x0), b = make_cloth_springs(m, x0);
  ASSERT_EQ(a.list.size(), b.list.size());
  EXPECT_EQ(a.damped, b.damped);
  for (size_t k = 0; k < a.list.size(); ++k) {
    EXPECT_EQ(a.list[k].a, b.list[k].a) << k;
    EXPECT_EQ(a.list[k].b, b.list[k].b) << k;
    EXPECT_EQ(a.list[k].k, b.list[k].k) << k;
    EXPECT_EQ(a.list[k].rest, b.list[k].rest) << k;
  }
  EXPECT_EQ(a.incident_start, b.incident_start);
}

// Bending across every interior edge: a triangle pair's opposite corners; none across a boundary edge.
// The irregular patch written as ASCII PLY is read by assimp in a child process (core/mesh_import.h): the
// same vertices (to float precision, assimp's) and the same faces, its quads kept as quads.
TEST(ClothMesh, APlyReadThroughTheChildKeepsItsQuads) {
  test::MeshDir dir;
  const ClothMesh obj = read_cloth_mesh(test::write_irregular_obj(dir.path(), Vec3::Zero(), 1.0), "");
  const auto ply = dir.path() / "irregular.ply";
  {
    std::ofstream out(ply);
    out << "ply\nformat ascii 1.0\nelement vertex " << obj.vertices.size()
        << "\nproperty double x\nproperty double y\nproperty double z\nelement face " << obj.faces.size()
        << "\nproperty list uchar int vertex_indices\nend_header\n";
    out.precision(17);
    for (const Vec3& p : obj.vertices) out << p.x() << " " << p.y() << " " << p.z() << "\n";
    for (const auto& f : obj.faces) {
      out << f.size();
      for (int v : f) out << " " << v;
      out << "\n";
    }
  }
  const ClothMesh m = read_cloth_mesh(ply, "");
  ASSERT_EQ(m.vertices.size(), obj.vertices.size());
  ASSERT_EQ(m.faces.size(), obj.faces.size());
  // Each face as its corners' positions, in order from its lowest corner: the same list for both files.
  auto faces_by_position = [](const ClothMesh& c) {
    std::vector<std::vector<std::array<long, 3>>> out;
    for (const auto& f : c.faces) {
      std::vector<std::array<long, 3>> corners;
      for (int v : f) {
        const Vec3 p = c.vertices[size_t(v)] * 1e5;
        corners.push_back({std::lround(p.x()), std::lround(p.y()), std::lround(p.z())});
      }
      std::rotate(corners.begin(), std::min_element(corners.begin(), corners.end()), corners.end());
      out.push_back(corners);
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  EXPECT_EQ(faces_by_position(m), faces_by_position(obj));
  EXPECT_GT(std::count_if(m.faces.begin(), m.faces.end(), [](const auto& f) { return f.size() == 4; }), 10);
}

TEST(ClothMesh, TrianglePairsGetOneBendingSpringAcrossTheirSharedEdge) {
  test::MeshDir dir;
  const auto file = dir.path() / "pair.obj";
  test::write_obj(file, {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 1), Vec3(0, 0, 1)}, {{0, 1, 2}, {0, 2, 3}});
  const ClothSpec c = *parse_scene(R"({"cloth": {"mesh": {"file": ")" + file.string() + R"("}, "imperfection": 0}})",
                                   dir.path() / "m.json").cloth;
  const ClothSprings s = make_cloth_springs(c, mesh_rest_positions(c));
  ASSERT_EQ(s.damped, 5);  // 5 edges, no quad diagonals
  ASSERT_EQ(s.list.size(), 6u);
  EXPECT_EQ(s.list[5].a, 1);
  EXPECT_EQ(s.list[5].b, 3);
  EXPECT_EQ(s.list[5].k, c.bend);
  EXPECT_NEAR(s.list[5].rest, std::sqrt(2.0), 1e-15);
}

TEST(ClothMeshForces, EveryTermMatchesFiniteDifferencesCompressedStretchedAndInContact) {
  test::MeshDir dir;
  const auto sheet = test::term_sheet(irregular_cloth(dir.path()));
  ASSERT_EQ(sheet->particles(), 35);
  for (double squeeze : {0.8, 0.97, 1.06}) {
    SCOPED_TRACE(squeeze);
    VecX x, v;
    test::perturbed_state(*sheet, squeeze, 0.004, 0.3, 5, x, v);
    const test::TermCheck spring = test::check_term(test::TermProbe<SpringTerm>(*sheet), x, v, 6, 2e-7);
    EXPECT_GT(spring.energy_gradient, 0);
    EXPECT_GT(spring.adjoint_x, 0);
    const test::TermCheck damping = test::check_term(test::TermProbe<SpringDampingTerm>(*sheet), x, v, 8);
    EXPECT_GT(damping.force, 0);
    EXPECT_GT(damping.adjoint_x, 0);
    const test::TermCheck gravity = test::check_term(test::TermProbe<GravityTerm>(*sheet), x, v, 2);
    EXPECT_GT(gravity.energy_gradient, 0);
    const test::TermCheck drag = test::check_term(test::TermProbe<AirDragTerm>(*sheet), x, v, 4);
    EXPECT_GT(drag.force, 0);
  }
  const char* colliders[] = {
      R"({"type": "ground", "center": [0, 0, 0], "axis": [0, 1, 0], "thickness": 0.03, "stiffness": 3000,
          "friction": 0.5})",
      R"({"type": "sphere", "center": [0, -0.2, 0], "radius": 0.21, "thickness": 0.03, "stiffness": 3000,
          "friction": 0.4})",
  };
  for (const char* col : colliders)
    for (double speed : {1e-4, 0.3}) {
      SCOPED_TRACE(std::string(col) + " speed " + std::to_string(speed));
      const auto touching = test::term_sheet(irregular_cloth(dir.path(), std::string(R"(, "colliders": [)") + col + "]"));
      VecX x, v;
      test::perturbed_state(*touching, 0.95, 0.004, speed, 9, x, v);
      const test::TermCheck contact = test::check_term(test::TermProbe<ContactTerm>(*touching), x, v, 10);
      EXPECT_GT(contact.force, 0) << "no contact: the check would not cover it";
      EXPECT_GT(contact.adjoint_x, 0);
      const test::TermCheck friction = test::check_term(test::TermProbe<FrictionTerm>(*touching), x, v, 12);
      EXPECT_GT(friction.force, 0) << "no friction: the check would not cover it";
      EXPECT_GT(friction.adjoint_v, 0);
    }
}

// Self contact reports no energy (a pair's force is gathered per particle; collider.h): the same term with
// the energy check left out, its force, definite blocks and adjoint shares checked.
class PairContactTerm : public ContactTerm {
 public:
  using ContactTerm::ContactTerm;
  static constexpr double ClothEnergy::*kEnergy = nullptr;
};

// Self contact (`cloth.self`'s term, particle pairs) on the irregular patch folded over, its two layers 6 mm
// apart with each upper vertex about 7 mm from its lower twin, sliding across each other: the pair forces with
// their cross couplings and the pair friction, against central differences at two step sizes, squeezed and
// stretched.
TEST(ClothMeshForces, SelfContactOfAFoldedIrregularMeshMatchesFiniteDifferences) {
  test::MeshDir dir;
  const auto file = test::write_folded_irregular_obj(dir.path(), Vec3(0, 0.02, 0), 0.3, 0.006, Vec3(0.003, 0, 0.002));
  const std::string cloth = R"({"mesh": {"file": ")" + file.string() + R"("}, "mass": 0.1})";
  for (double squeeze : {0.97, 1.03})
    for (double speed : {1e-4, 0.3}) {
      SCOPED_TRACE("squeeze " + std::to_string(squeeze) + " speed " + std::to_string(speed));
      auto sheet = test::term_sheet(cloth);
      ASSERT_EQ(sheet->particles(), 70);  // each layer's notch corner is in no face
      auto self = std::make_unique<SelfCollider>(sheet->particles(), 0.01, 500.0, 0.5 * 0.01);
      self->set_friction({0.3, 0.01});
      SelfCollider* pairs = self.get();
      sheet->colliders.push_back(std::move(self));
      sheet->prepare = [pairs](const VecX& x, const VecX& v) { pairs->update(x, v); };
      VecX x, v;
      test::perturbed_state(*sheet, squeeze, 0.0005, speed, 17, x, v);
      pairs->set_counting(true);
      const test::TermCheck contact = test::check_term(test::TermProbe<PairContactTerm>(*sheet), x, v, 18);
      EXPECT_GT(pairs->take_count(), 0) << "no pair in contact";
      EXPECT_GT(contact.force, 0);
      EXPECT_GT(contact.adjoint_x, 0);
      const test::TermCheck friction = test::check_term(test::TermProbe<FrictionTerm>(*sheet), x, v, 19);
      EXPECT_GT(friction.force, 0) << "no pair friction";
      EXPECT_GT(friction.adjoint_x, 0);
      EXPECT_GT(friction.adjoint_v, 0);
    }
}

// The whole step's exact adjoint (keyframe gradcheck) on the irregular patch, pinned by a region, lying on a
// sphere and sliding on the ground, at zero and perturbed controls, per-step forces and the 3 x 3 lattice.
TEST(ClothMeshAdjoint, MatchesFiniteDifferencesInContactAtPerturbedControls) {
  test::MeshDir dir;
  const auto file = test::write_irregular_obj(dir.path(), Vec3(0, 0.12, 0), 0.5);
  struct Case {
    const char* name;
    std::string cloth, controls, objectives;
  };
  const Case cases[] = {
      {"sphere_region_pinned",
       R"("pins": {"min": [-1, -1, 0.2], "max": [1, 1, 1]},
          "colliders": [{"type": "sphere", "center": [0, 0, 0], "radius": 0.1, "thickness": 0.03, "stiffness": 3000}])",
       R"({"kind": "per_step", "alpha": 1e-4})",
       R"([{"type": "center_of_mass", "frame": 3, "weight": 100, "target": [0.05, 0.2, 0]}])"},
      {"ground_sliding_lattice",
       R"("velocity": [1.5, -0.05, 0.4],
          "colliders": [{"type": "ground", "center": [0, 0.11, 0], "thickness": 0.03, "stiffness": 3000, "friction": 0.6}])",
       R"({"kind": "per_frame", "alpha": 1e-4})",
       R"([{"type": "position", "frame": 3, "weight": 100, "particles": {"min": [-1, -1, -1], "max": [0, 1, 0]},
            "targets": [[0.1, 0.15, 0.1]]}])"},
  };
  for (const Case& c : cases) {
    const std::string& cloth = c.cloth;
    for (int substeps : {1, 4}) {
      Scene scene = parse_scene(
          std::string(R"({"time": {"fps": 30, "frames": 3, "substeps": )") + std::to_string(substeps) +
              R"(}, "cloth": {"mesh": {"file": ")" + file.string() + R"("}, "mass": 0.1, "solver": "direct", )" + cloth +
              R"(}, "controls": )" + c.controls + R"(, "objectives": )" + c.objectives + "}",
          dir.path() / (std::string(c.name) + ".json"));
      // Forces on the 3 x 3 lattice over the mesh (a stage's controls, not a scene's).
      if (std::string(c.name).ends_with("lattice")) scene.controls.kind = ControlKind::kPerFrameLattice;
      auto sys = make_system(scene);
      Problem problem(scene, scene.time, *sys);
      test::gradcheck_perturbed(problem, 1e-4, {0.0, 0.01, 0.1}, [&](double perturb, const GradcheckResult& r) {
        std::printf("%s h = 1/%d, perturb %g: max_rel_error %.2e, fd_spread %.2e, %d checked\n", c.name,
                    30 * substeps, perturb, r.max_rel_error, r.fd_spread, r.checked);
        ASSERT_GT(r.grad_norm, 0) << c.name;
        EXPECT_GE(r.checked, 14) << c.name;
        EXPECT_LE(r.max_rel_error, 1e-6) << c.name << " h = 1/" << 30 * substeps << " perturb " << perturb;
      });
    }
  }
}

// The whole step's exact adjoint with `cloth.self` on the folded irregular mesh: the upper layer slides over
// the lower (pair contact and pair friction from the first step: the scene's objective differs without them),
// per-step and per-frame forces at zero and perturbed controls.
TEST(ClothMeshAdjoint, SelfContactOfAFoldedMeshMatchesFiniteDifferences) {
  test::MeshDir dir;
  const auto file = test::write_folded_irregular_obj(dir.path(), Vec3(0, 0.012, 0), 0.3, 0.007, Vec3(0.003, 0, 0.002));
  const std::string self = R"({"enabled": true, "thickness": 0.01, "stiffness": 500, "friction": 0.3})";
  for (const char* controls : {R"({"kind": "per_step", "alpha": 1e-4})", R"({"kind": "per_frame", "alpha": 1e-4})"})
    for (int substeps : {1, 4}) {
      const Scene scene = test::folded_mesh_scene(dir.path(), file, controls, substeps, self);
      auto sys = make_system(scene);
      Problem problem(scene, scene.time, *sys);
      {
        const Scene apart = test::folded_mesh_scene(dir.path(), file, controls, substeps, R"({"enabled": false})");
        auto apart_sys = make_system(apart);
        Problem apart_problem(apart, apart.time, *apart_sys);
        const VecX z = problem.initial_guess();
        const double with = problem.evaluate(z, nullptr), without = apart_problem.evaluate(z, nullptr);
        // φ's round-off here is ~1e-12 of itself (direct solve); the pair forces move it by ~1e-4 of itself.
        std::printf("self contact moves phi by %.2e of itself\n", std::abs(with - without) / std::abs(without));
        EXPECT_GT(std::abs(with - without), 1e-5 * std::abs(without)) << "the layers never touched";
      }
      test::gradcheck_perturbed(problem, 1e-4, {0.0, 0.01, 0.1}, [&](double perturb, const GradcheckResult& r) {
        std::printf("folded self contact %s h = 1/%d, perturb %g: max_rel_error %.2e, fd_spread %.2e, %d checked\n",
                    controls, 30 * substeps, perturb, r.max_rel_error, r.fd_spread, r.checked);
        ASSERT_GT(r.grad_norm, 0);
        EXPECT_GE(r.checked, 14);
        EXPECT_LE(r.fd_spread, 1e-6) << "the differences' steps disagree";
        EXPECT_LE(r.max_rel_error, 1e-6) << controls << " h = 1/" << 30 * substeps << " perturb " << perturb;
      });
    }
}

// Runs `steps` steps of the scene's cloth from its start with no control; the positions after each.
std::vector<VecX> motion(const Scene& scene, int steps) {
  auto sys = make_system(scene);
  VecX x, v, x1, v1, u = VecX::Zero(3 * scene.particles());
  sys->initial_state(x, v);
  auto record = sys->new_record();
  std::vector<VecX> out;
  for (int n = 0; n < steps; ++n) {
    EXPECT_TRUE(sys->step(n, x, v, u, x1, v1, *record)) << "step " << n;
    x.swap(x1);
    v.swap(v1);
    out.push_back(x);
  }
  return out;
}

// A grid and the same grid read from an OBJ file (quads) with even masses move identically: the same
// particles, springs in the same order, the same imperfection and masses. With masses by area (the mesh's
// default) its edges and corners are lighter, and the motion differs (measured, printed).
TEST(ClothMeshEquivalence, AGridAndTheSameGridAsAnObjGiveTheSameMotion) {
  test::MeshDir dir;
  const std::string sheet = R"("mass": 0.2, "pins": [0, 9], "cg_tolerance": 1e-10,
      "colliders": [{"type": "sphere", "center": [0.1, -0.15, 0.2], "radius": 0.2, "thickness": 0.02, "stiffness": 3000, "friction": 0.3}])";
  const std::string time = R"("time": {"fps": 30, "frames": 20, "substeps": 2})";
  const Scene grid = parse_scene(R"({)" + time + R"(, "cloth": {"nx": 10, "ny": 8, "width": 0.5, "height": 0.4,
      "origin": [-0.25, 0.1, -0.1], "v_axis": [0, 0, 1], )" + sheet + "}}", dir.path() / "grid.json");
  const auto file = test::write_grid_obj(dir.path(), *grid.cloth);
  auto mesh_scene = [&](const char* mass_by) {
    return parse_scene(R"({)" + time + R"(, "cloth": {"mesh": {"file": ")" + file.string() + R"("}, "mass_by": ")" +
                           mass_by + R"(", )" + sheet + "}}",
                       dir.path() / "mesh.json");
  };
  const int steps = 40;
  const std::vector<VecX> a = motion(grid, steps), b = motion(mesh_scene("uniform"), steps),
                          c = motion(mesh_scene("area"), steps);
  double same = 0, area = 0, travel = 0;
  for (int n = 0; n < steps; ++n) {
    same = std::max(same, (a[size_t(n)] - b[size_t(n)]).cwiseAbs().maxCoeff());
    area = std::max(area, (a[size_t(n)] - c[size_t(n)]).cwiseAbs().maxCoeff());
    travel = std::max(travel, (a[size_t(n)] - a[0]).cwiseAbs().maxCoeff());
  }
  std::printf("grid vs OBJ over %d steps (largest travel %.3f m): even masses %.3e m, masses by area %.3e m\n", steps,
              travel, same, area);
  EXPECT_EQ(same, 0.0);
  EXPECT_GT(travel, 0.05);
  EXPECT_GT(area, 1e-4);  // a different cloth: the comparison would see it
}

TEST(ClothMeshSpec, PinsAndKeyframeParticlesByRegionOfTheRestShape) {
  test::MeshDir dir;
  const auto file = test::write_irregular_obj(dir.path(), Vec3::Zero(), 1.0);
  const Scene s = parse_scene(R"({"cloth": {"mesh": {"file": ")" + file.string() +
                                  R"(", "up_axis": "z", "scale": 2, "offset": [0, 1, 0]},
      "pins": {"min": [-5, -5, -5], "max": [5, 0.1, 5]}},
      "objectives": [{"type": "center_of_mass", "frame": 1, "particles": {"min": [0.5, -5, -5], "max": [5, 5, 5]},
                      "target": [0, 0, 0]}]})",
                              dir.path() / "s.json");
  // z up: the file's x-z plane (y = 0) becomes the x-y plane at z = 0 after (x, y, z) -> (x, z, -y), scaled
  // by 2 (x and y in [-1, 1], jittered) and lifted by 1 m.
  for (const Vec3& p : s.cloth->mesh->vertices) {
    EXPECT_EQ(p.z(), 0.0);
    EXPECT_NEAR(p.y(), 1.0, 1.0 + 0.1);
  }
  ASSERT_FALSE(s.cloth->pins.empty());
  for (int i : s.cloth->pins) EXPECT_LE(s.cloth->mesh->vertices[size_t(i)].y(), 0.1);
  EXPECT_LT(s.cloth->pins.size(), 35u);
  ASSERT_FALSE(s.objectives[0].particles.empty());
  for (int i : s.objectives[0].particles) EXPECT_GE(s.cloth->mesh->vertices[size_t(i)].x(), 0.5);
}

std::string load_error(const std::string& text, const std::filesystem::path& file) {
  try {
    parse_scene(text, file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// OBJ's "g" and "o" lines name vertex sets: pins and keyframe particles by name, in the compacted order (a
// vertex no face uses is left out before them), and an unknown name lists the file's names.
TEST(ClothMeshSpec, PinsAndKeyframeParticlesByTheFilesNamedGroups) {
  test::MeshDir dir;
  // A 3 x 2 strip of two quads with an unused vertex first; the left quad in group "hem", the right in "tip".
  std::ofstream(dir.path() / "strip.obj") << "v 9 9 9\n"
                                              "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\n"
                                              "o Strip\ng hem\nf 2 3 6 5\ng tip\nf 3 4 7 6\n";
  const std::string text = R"({"cloth": {"mesh": {"file": "strip.obj"}, "pins": {"group": "hem"}},
      "objectives": [{"type": "center_of_mass", "frame": 1, "particles": {"group": "tip"}, "target": [0, 0, 0]}]})";
  const Scene s = parse_scene(text, dir.path() / "s.json");
  ASSERT_EQ(s.cloth->particles(), 6);
  EXPECT_EQ(s.cloth->pins, (std::vector<int>{0, 1, 3, 4}));
  EXPECT_EQ(s.objectives[0].particles, (std::vector<int>{1, 2, 4, 5}));
  EXPECT_EQ(s.cloth->mesh->groups.at("Strip"), (std::vector<int>{0, 1, 2, 3, 4, 5}));
  std::string bad = text;
  bad.replace(bad.find(R"("group": "tip")"), 14, R"("group": "tail")");
  EXPECT_NE(load_error(bad, dir.path() / "s.json")
                .find("/objectives/0/particles/group: expected a vertex set "),
            std::string::npos)
      << load_error(bad, dir.path() / "s.json");
  EXPECT_NE(load_error(bad, dir.path() / "s.json").find("(it names \"Strip\", \"hem\", \"tip\"), got \"tail\""),
            std::string::npos);
  // A grid has no named sets.
  EXPECT_NE(load_error(R"({"cloth": {"pins": {"group": "hem"}}})", dir.path() / "s.json").find("/cloth/pins/group"),
            std::string::npos);
}

// A run directory's copy of the scene names the mesh file absolutely, so render and export read it there.
TEST(ClothMeshSpec, ARunsSceneCopyNamesTheMeshFileAbsolutely) {
  nlohmann::json j = nlohmann::json::parse(R"({"cloth": {"mesh": {"file": "../assets/cloth/flag.obj"}}})");
  absolutise_scene_paths(j, "/data/shots/scenes");
  EXPECT_EQ(j["cloth"]["mesh"]["file"], "/data/shots/assets/cloth/flag.obj");
}

TEST(ClothMeshSpec, BadMeshInputIsOneClearErrorNamingTheFileAndField) {
  test::MeshDir dir;
  const auto scene = dir.path() / "s.json";
  auto cloth = [](const std::string& mesh, const std::string& extra = "") {
    return R"({"cloth": {"mesh": )" + mesh + extra + "}}";
  };
  EXPECT_NE(load_error(cloth(R"({"file": "missing.obj"})"), scene).find("missing.obj: cloth mesh not found"),
            std::string::npos);
  const auto fifo = dir.path() / "fifo.obj";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(load_error(cloth(R"({"file": "fifo.obj"})"), scene).find("fifo.obj: cloth mesh not found"), std::string::npos);
  const auto file = test::write_irregular_obj(dir.path(), Vec3::Zero(), 1.0);
  EXPECT_NE(load_error(cloth(R"({"file": "irregular.obj", "name": "Flag"})"), scene)
                .find("no object or group named \"Flag\" (the file has \"Cloth\")"),
            std::string::npos);
  EXPECT_NE(load_error(cloth(R"({"file": "irregular.obj"})", R"(, "nx": 4)"), scene).find("/cloth"), std::string::npos);
  EXPECT_NE(load_error(cloth(R"({"file": "irregular.obj"})", R"(, "pins": "top_edge")"), scene).find("/cloth/pins"),
            std::string::npos);
  EXPECT_NE(load_error(cloth(R"({"file": "irregular.obj"})", R"(, "pins": {"min": [5, 5, 5], "max": [6, 6, 6]})"), scene)
                .find("/cloth/pins/min"),
            std::string::npos);
  std::ofstream(dir.path() / "bad.obj") << "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 7\n";
  EXPECT_NE(load_error(cloth(R"({"file": "bad.obj"})"), scene).find("bad.obj: line 4: face corner 7 names no vertex"),
            std::string::npos);
  std::ofstream(dir.path() / "nan.obj") << "v 0 0 nan\n";
  EXPECT_NE(load_error(cloth(R"({"file": "nan.obj"})"), scene).find("nan.obj: line 1"), std::string::npos);
  std::ofstream(dir.path() / "empty.obj") << "v 0 0 0\n";
  EXPECT_NE(load_error(cloth(R"({"file": "empty.obj"})"), scene).find("no faces"), std::string::npos);
  std::ofstream(dir.path() / "twin.obj") << "v 0 0 0\nv 1 0 0\nv 1 0 0\nf 1 2 3\n";
  EXPECT_NE(load_error(cloth(R"({"file": "twin.obj"})"), scene).find("twin.obj: vertices 1 and 2 coincide"),
            std::string::npos);
  (void)file;
}

}  // namespace
}  // namespace kf

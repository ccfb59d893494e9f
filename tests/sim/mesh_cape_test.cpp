// A mesh cloth worn by a character (a poncho): its pins follow the skin from where they rest, and the
// adjoint gradient with the body in contact matches central finite differences.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include "adjoint/rollout.h"
#include "core/error.h"
#include "opt/gradcheck.h"
#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/cape/cape_system.h"
#include "sim/make_system.h"
#include "character_test_util.h"
#include "gradient_test_helpers.h"

namespace kf {
namespace {

// A 0.6 m square poncho of 0.1 m quads with the four around its centre left out (the neck hole), Y up.
void write_small_poncho(const std::filesystem::path& file) {
  std::ofstream f(file);
  for (int k = 0; k < 7; ++k)
    for (int i = 0; i < 7; ++i) f << "v " << -0.3 + 0.1 * i << " 0 " << -0.3 + 0.1 * k << "\n";
  for (int k = 0; k < 6; ++k)
    for (int i = 0; i < 6; ++i) {
      if ((i == 2 || i == 3) && (k == 2 || k == 3)) continue;
      const int a = k * 7 + i + 1;
      f << "f " << a << " " << a + 7 << " " << a + 8 << " " << a + 1 << "\n";
    }
}

// The poncho over the file-frame character's shoulders, its collar (the ring round the hole) pinned.
std::string poncho_scene(const std::string& mesh, int frames, int substeps, const std::string& extra) {
  return R"({"time": {"fps": 30, "substeps": )" + std::to_string(substeps) + R"(, "frames": )" +
         std::to_string(frames) + R"(},
    "cloth": {"mesh": {"file": ")" + mesh + R"(", "offset": [0, 0.56, -0.15]}, "mass": 0.2,
              "pins": {"min": [-0.11, 0.5, -0.26], "max": [0.11, 0.6, -0.04]},
              "stretch": 200, "shear": 20, "bend": 1, "damping": 0.02, "cg_tolerance": 1e-12,
              "cg_max_iterations": 5000)" + extra + R"(},
    "character": {"file": ")" + test::character_asset().string() + R"(", "time": [[0, 0.3], [6, 0.9]],
                  "body": {"thickness": 0.03, "stiffness": 500, "search": 0.08}, "self": {"enabled": false}}})";
}

TEST(MeshCape, CollarFollowsTheSkinFromWhereItRests) {
  test::TempDir dir;
  write_small_poncho(dir.path() / "poncho.obj");
  const Scene scene = parse_scene(poncho_scene("poncho.obj", 6, 2, ""), dir.path() / "poncho.json");
  ASSERT_EQ(scene.cloth->pins.size(), 8u);  // the ring of eight vertices round the hole
  auto sys = make_system(scene);
  auto* cape = dynamic_cast<CapeSystem*>(sys.get());
  ASSERT_NE(cape, nullptr);
  VecX x0, v0;
  sys->initial_state(x0, v0);
  Rollout r;
  ASSERT_TRUE(simulate(*sys, x0, v0, std::vector<VecX>(scene.time.steps(), VecX::Zero(sys->dof())), r));
  // Each pin: the torso vertex nearest it at step 0 carries it (same displacement at every step).
  const auto& names = cape->character().mesh_names();
  const size_t torso = size_t(std::find(names.begin(), names.end(), "Torso") - names.begin());
  ASSERT_LT(torso, names.size());
  const int begin = cape->character().mesh_vertex_begin()[torso], end = cape->character().mesh_vertex_begin()[torso + 1];
  const VecX body0 = cape->body_at(0);
  double moved = 0;
  for (int p : scene.cloth->pins) {
    const Vec3 rest = scene.cloth->mesh->vertices[size_t(p)];
    EXPECT_LT((seg(r.x[0], p) - rest).norm(), 1e-12) << "pin " << p << " jumps at frame 0";
    int nearest = begin;
    for (int v = begin; v < end; ++v)
      if ((seg(body0, v) - rest).squaredNorm() < (seg(body0, nearest) - rest).squaredNorm()) nearest = v;
    for (int n : {1, 5, 12}) {
      const VecX body = cape->body_at(n);
      EXPECT_LT((seg(r.x[n], p) - seg(r.x[0], p) - (seg(body, nearest) - seg(body0, nearest))).norm(), 1e-12)
          << "pin " << p << " step " << n;
      moved = std::max(moved, (seg(r.x[n], p) - seg(r.x[0], p)).norm());
    }
  }
  EXPECT_GT(moved, 0.01);  // the body moves the collar, so the check is not on a still character
  EXPECT_GT(sys->run_stats()[0].second, 0) << "the poncho never touched the shoulders";
}

TEST(MeshCape, WithoutPinsItIsRefusedNamingThePins) {
  test::TempDir dir;
  write_small_poncho(dir.path() / "poncho.obj");
  std::string text = poncho_scene("poncho.obj", 3, 1, "");
  text.replace(text.find(R"("pins")"), text.find(R"("stretch")") - text.find(R"("pins")"), "");
  const Scene scene = parse_scene(text, dir.path() / "poncho.json");
  try {
    make_system(scene);
    FAIL() << "a mesh cloth on a character without pins was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/cloth/pins: a mesh cloth on a character needs pins"), std::string::npos)
        << e.what();
  }
}

// keyframe gradcheck's check with the shoulders in contact: per-frame forces at two step lengths, at zero and
// perturbed controls, to 1e-6 on every checked sample.
TEST(MeshCape, GradcheckWithBodyContactAtTwoStepsAndPerturbedControls) {
  test::TempDir dir;
  write_small_poncho(dir.path() / "poncho.obj");
  for (int substeps : {2, 8}) {
    std::string text = poncho_scene("poncho.obj", 4, substeps, R"(, "solver": "direct")");
    text.insert(text.rfind('}'), R"(, "controls": {"kind": "per_frame", "alpha": 1e-4},
      "objectives": [{"type": "center_of_mass", "frame": 4, "weight": 100, "target": [0, 0.4, 0.2]}])");
    const Scene scene = parse_scene(text, dir.path() / "poncho-gradcheck.json");
    auto sys = make_system(scene);
    Problem problem(scene, scene.time, *sys);
    test::gradcheck_perturbed(problem, 1e-4, {0.0, 0.01, 0.1}, [&](double perturb, const GradcheckResult& r) {
      const double body = sys->run_stats()[0].second;
      std::printf("h = 1/%d, perturb %g: max_rel_error %.2e, fd_spread %.2e, %d checked, %d kinks, %g body contacts\n",
                  30 * substeps, perturb, r.max_rel_error, r.fd_spread, r.checked, r.kinks, body);
      EXPECT_GT(body, 0) << "no body contact: the check would not cover it";
      EXPECT_GE(r.checked, 14) << "h = 1/" << 30 * substeps << " perturb " << perturb;
      EXPECT_LE(r.max_rel_error, 1e-6) << "h = 1/" << 30 * substeps << " perturb " << perturb;
    });
  }
}

}  // namespace
}  // namespace kf

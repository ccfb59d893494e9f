// cloth.self's whole-run adjoint at a fine step (h = 1/240): the folded irregular mesh, its two layers
// closer than the self-contact thickness from the first step, sliding over each other on the ground, per-step
// and per-frame forces at perturbed controls, central differences at two step sizes (eps 2e-4 and 1e-4).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/make_system.h"
#include "cloth_mesh_test_util.h"
#include "gradient_test_helpers.h"

namespace kf {
namespace {

constexpr int kSubsteps = 8;  // 30 frames a second: h = 1/240

TEST(SelfContactFineStep, FoldedSheetsWholeRunGradientMatchesFiniteDifferences) {
  test::MeshDir dir;
  const auto file = test::write_folded_irregular_obj(dir.path(), Vec3(0, 0.012, 0), 0.3, 0.007, Vec3(0.003, 0, 0.002));
  const char* self = R"({"enabled": true, "thickness": 0.01, "stiffness": 500, "friction": 0.3})";
  for (const char* controls : {R"({"kind": "per_step", "alpha": 1e-4})", R"({"kind": "per_frame", "alpha": 1e-4})"}) {
    const Scene scene = test::folded_mesh_scene(dir.path(), file, controls, kSubsteps, self);
    auto sys = make_system(scene);
    Problem problem(scene, scene.time, *sys);
    const Scene apart = test::folded_mesh_scene(dir.path(), file, controls, kSubsteps, R"({"enabled": false})");
    auto apart_sys = make_system(apart);
    Problem apart_problem(apart, apart.time, *apart_sys);
    for (double perturb : {0.01, 0.1}) {
      const VecX z = test::perturbed_controls(problem, perturb, 3);
      const double with = problem.evaluate(z, nullptr), without = apart_problem.evaluate(z, nullptr);
      EXPECT_GT(std::abs(with - without), 1e-5 * std::abs(without)) << "the layers never touched";
      double grad_norm[2] = {0, 0};
      int k = 0;
      // Steps at which φ's round-off stays below the bound (eps 1e-5 does not: tests/results/shots/README.md).
      for (double eps : {2e-4, 1e-4}) {
        const GradcheckResult r = gradcheck(problem, z, {.samples = 16, .eps = eps, .seed = 5});
        std::printf("self contact h = 1/%d %s perturb %g eps %g: max_rel_error %.2e, fd_spread %.2e, %d checked, "
                    "%d kinks, phi moved by self contact %.2e of itself\n",
                    30 * kSubsteps, controls, perturb, eps, r.max_rel_error, r.fd_spread, r.checked, r.kinks,
                    std::abs(with - without) / std::abs(without));
        ASSERT_GT(r.grad_norm, 0);
        EXPECT_GE(r.checked, 14) << controls << " eps " << eps;
        EXPECT_LE(r.fd_spread, 1e-6) << "the differences' steps disagree";
        EXPECT_LE(r.max_rel_error, 1e-6) << controls << " perturb " << perturb << " eps " << eps;
        grad_norm[k++] = r.grad_norm;
      }
      EXPECT_EQ(grad_norm[0], grad_norm[1]);  // the same adjoint, checked twice
    }
  }
}

}  // namespace
}  // namespace kf

// The cape system: pins follow the skinned shoulders, the scene block's errors, and the adjoint gradient
// (with body and self contacts active) against central finite differences.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "adjoint/rollout.h"
#include "core/error.h"
#include "opt/gradcheck.h"
#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/cape/anchor_track.h"
#include "sim/cape/cape_system.h"
#include "sim/character/cape_anchors.h"
#include "sim/make_system.h"
#include "character_test_util.h"
#include "gradient_test_helpers.h"

namespace kf {
namespace {

// A small cape, 0.43 m wide and 0.5 m long, behind the back of the file-frame character.
std::string cape_scene(int nx, int ny, double self_thickness, const std::string& time_keys, int frames,
                       int substeps) {
  return R"({"time": {"fps": 30, "substeps": )" + std::to_string(substeps) + R"(, "frames": )" +
         std::to_string(frames) + R"(},
    "cloth": {"nx": )" + std::to_string(nx) + R"(, "ny": )" + std::to_string(ny) + R"(,
              "width": 0.43, "height": 0.5, "origin": [-0.215, -0.03, -0.3], "mass": 0.2,
              "pins": "top_edge", "stretch": 200, "shear": 20, "bend": 1, "damping": 0.02,
              "cg_tolerance": 1e-12, "cg_max_iterations": 5000},
    "character": {"file": ")" + test::character_asset().string() + R"(", "time": )" + time_keys + R"(,
                  "body": {"thickness": 0.02, "stiffness": 500, "search": 0.06},
                  "self": {"thickness": )" + std::to_string(self_thickness) + R"(, "stiffness": 50}}})";
}

TEST(CapeSystem, PinnedEdgeFollowsTheShoulderAnchors) {
  const Scene scene = parse_scene(cape_scene(6, 5, 0.01, "[[0, 1.2], [6, 1.5]]", 6, 2), "cape.json");
  auto sys = make_system(scene);
  auto* cape = dynamic_cast<CapeSystem*>(sys.get());
  ASSERT_NE(cape, nullptr);
  VecX x0, v0;
  sys->initial_state(x0, v0);
  Rollout r;
  ASSERT_TRUE(simulate(*sys, x0, v0, std::vector<VecX>(scene.time.steps(), VecX::Zero(sys->dof())), r));
  const std::vector<int> anchors = cape_anchor_vertices(cape->character(), scene.character->anchors);
  const int nx = 6, top = 4 * nx;
  double moved = 0;
  for (int n : {0, 5, 12}) {
    VecX a;
    gather_vertices(cape->body_at(n), anchors, a);
    EXPECT_LT((seg(r.x[n], top) - seg(a, 0)).norm(), 1e-12) << "step " << n;
    EXPECT_LT((seg(r.x[n], top + nx - 1) - seg(a, 4)).norm(), 1e-12) << "step " << n;
    moved = std::max(moved, (seg(r.x[n], top) - seg(r.x[0], top)).norm());
  }
  EXPECT_GT(moved, 0.01);  // the jump moves the shoulders, so the check is not on a still character
  EXPECT_DOUBLE_EQ(cape->animation_time_at(6), 1.2 + 0.3 * 3 / 6);
}

TEST(CapeSystem, PolylinePointsAreEvenlySpacedByArcLength) {
  const std::vector<Vec3> pts{{0, 0, 0}, {1, 0, 0}, {1, 2, 0}};
  const auto q = polyline_points(pts, {0.0, 0.5, 1.0});
  EXPECT_LT((q[0] - pts[0]).norm(), 1e-15);
  EXPECT_LT((q[1] - Vec3(1, 0.5, 0)).norm(), 1e-15);
  EXPECT_LT((q[2] - pts[2]).norm(), 1e-15);
}

TEST(CapeSystem, SceneErrorsNameTheKey) {
  std::string s = cape_scene(4, 4, 0.01, "[[0, 0], [0, 1]]", 4, 1);
  try {
    parse_scene(s, "bad.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/character/time/1"), std::string::npos) << e.what();
  }
  s = cape_scene(4, 4, 0.01, "[[0, 0]]", 4, 1);
  s.replace(s.find("\"time\": [[0, 0]]"), 16, "\"time\": [[0, 0]], \"start\": {\"run\": \"nowhere\"}");
  EXPECT_THROW(parse_scene(s, "bad.json"), InputError);
}

using test::EndTarget;

struct Agreement {
  double cosine, relative_error, body_contacts, self_contacts;
};

// The cape starts flat and at rest with its top edge near the shoulder anchors of the bind pose (a start
// far from them, as the crouch, jolts the top rows, where the integrator-swapping adjoint is least
// accurate), then the character moves into the jump: the cape meets the back and, with a self thickness
// above the grid spacing, its neighbours push each other apart. Compared: d phi / d f for a constant force
// f on every particle, on every third free particle's components, against central differences.
Agreement gradient_agreement(int substeps, double self_thickness, AdjointKind adjoint) {
  std::string text = cape_scene(5, 5, self_thickness, "[[0, 0], [8, 0.4]]", 8, substeps);
  text.replace(text.find("[-0.215, -0.03, -0.3]"), 21, "[-0.215, -0.03, -0.24]");
  const Scene scene = parse_scene(text, "grad.json");
  auto sys = make_system(scene);
  dynamic_cast<CapeSystem&>(*sys).set_adjoint(adjoint);
  const int N = scene.time.steps(), dof = sys->dof();
  VecX x0, v0;
  sys->initial_state(x0, v0);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  VecX force(dof);
  for (int k = 0; k < dof; ++k) force[k] = 0.005 * U(rng);
  EndTarget cost;
  cost.last = N;
  cost.target = x0 + VecX::Constant(dof, 0.05);
  auto phi = [&](const VecX& f) {
    Rollout r;
    EXPECT_TRUE(simulate(*sys, x0, v0, std::vector<VecX>(N, f), r));
    return cost_value(cost, r);
  };
  Rollout r;
  std::vector<VecX> Uf(N, force), dU;
  EXPECT_TRUE(simulate(*sys, x0, v0, Uf, r));
  const auto stats = sys->run_stats();
  VecX dx0, dv0;
  backward(*sys, r, Uf, cost, dU, dx0, dv0);
  VecX g = VecX::Zero(dof);
  for (const VecX& d : dU) g += d;
  std::vector<int> sample;
  for (int i = 0; i < 20; i += 3)  // rows 0-3 are free, the top row (20-24) is pinned
    for (int c = 0; c < 3; ++c) sample.push_back(3 * i + c);
  VecX a(sample.size()), fd(sample.size());
  const double eps = 1e-6;
  for (size_t j = 0; j < sample.size(); ++j) {
    VecX fp = force, fm = force;
    fp[sample[j]] += eps;
    fm[sample[j]] -= eps;
    fd[j] = (phi(fp) - phi(fm)) / (2 * eps);
    a[j] = g[sample[j]];
  }
  return {a.dot(fd) / (a.norm() * fd.norm()), (a - fd).norm() / fd.norm(), stats[0].second, stats[1].second};
}

// With body and self contacts active: the exact adjoint agrees with central differences to their own
// accuracy at both steps; the integrator-swapping adjoint's error shrinks as the step does.
TEST(CapeSystem, AdjointGradientMatchesFiniteDifferencesWithContacts) {
  const Agreement coarse = gradient_agreement(4, 0.09, AdjointKind::kExact),
                  fine = gradient_agreement(16, 0.09, AdjointKind::kExact);
  const Agreement swap_coarse = gradient_agreement(4, 0.09, AdjointKind::kSwap),
                  swap_fine = gradient_agreement(16, 0.09, AdjointKind::kSwap);
  std::printf("exact: h = 1/120 relative error %.2e, h = 1/480 %.2e; swap: h = 1/120 cosine %.5f, relative "
              "error %.4f, h = 1/480 cosine %.5f, relative error %.4f (%g body, %g self contacts)\n",
              coarse.relative_error, fine.relative_error, swap_coarse.cosine, swap_coarse.relative_error,
              swap_fine.cosine, swap_fine.relative_error, fine.body_contacts, fine.self_contacts);
  EXPECT_GT(fine.body_contacts, 0) << "no body contact: the check would not cover it";
  EXPECT_GT(fine.self_contacts, 0) << "no self contact: the check would not cover it";
  EXPECT_LT(coarse.relative_error, 1e-6);
  EXPECT_LT(fine.relative_error, 1e-6);
  EXPECT_GE(swap_fine.cosine, 0.99);
  EXPECT_LT(swap_fine.relative_error, swap_coarse.relative_error);
}

// One exact adjoint step in the middle of a run with body and self contacts, against central differences
// of S = xhat1 . x1 + vhat1 . v1 in x, v and u, on every coordinate (the pinned top row included).
TEST(CapeSystem, AdjointStepIsExact) {
  std::string text = cape_scene(5, 5, 0.12, "[[0, 0], [8, 0.4]]", 4, 4);
  text.replace(text.find("[-0.215, -0.03, -0.3]"), 21, "[-0.215, -0.03, -0.24]");
  const Scene scene = parse_scene(text, "step.json");
  auto sys = make_system(scene);
  const int dof = sys->dof(), m = 8;
  VecX x0, v0;
  sys->initial_state(x0, v0);
  Rollout r;
  ASSERT_TRUE(simulate(*sys, x0, v0, std::vector<VecX>(m + 1, VecX::Zero(dof)), r));
  const VecX &x = r.x[m], &v = r.v[m];
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  VecX xh1(dof), vh1(dof), u(dof), x1(dof), v1(dof);
  for (int k = 0; k < dof; ++k) xh1[k] = U(rng), vh1[k] = U(rng), u[k] = 0.01 * U(rng);
  VecX xh, vh, uh;
  sys->step_adjoint(m, x, v, u, xh1, vh1, xh, vh, uh);
  sys->step(m, x, v, u, x1, v1);
  const auto stats = sys->run_stats();
  EXPECT_GT(stats[0].second, 0);
  EXPECT_GT(stats[1].second, 0);
  auto S = [&](const VecX& y, const VecX& vv, const VecX& uu) {
    VecX a(dof), b(dof);
    sys->step(m, y, vv, uu, a, b);
    return xh1.dot(a) + vh1.dot(b);
  };
  double err[3] = {0, 0, 0}, norm[3] = {0, 0, 0};
  for (int k = 0; k < dof; ++k) {
    const double e = 1e-7;
    VecX p = x, q = x, pv = v, qv = v, pu = u, qu = u;
    p[k] += e, q[k] -= e, pv[k] += e, qv[k] -= e, pu[k] += e, qu[k] -= e;
    const double fx = (S(p, v, u) - S(q, v, u)) / (2 * e);
    const double fv = (S(x, pv, u) - S(x, qv, u)) / (2 * e), fu = (S(x, v, pu) - S(x, v, qu)) / (2 * e);
    err[0] += (xh[k] - fx) * (xh[k] - fx), norm[0] += fx * fx;
    err[1] += (vh[k] - fv) * (vh[k] - fv), norm[1] += fv * fv;
    err[2] += (uh[k] - fu) * (uh[k] - fu), norm[2] += fu * fu;
  }
  for (int c = 0; c < 3; ++c) EXPECT_LT(std::sqrt(err[c] / norm[c]), 1e-6) << "x, v, u"[3 * c];
}

// keyframe gradcheck's check on a cape that meets the back and itself within three frames: per-frame
// forces, at steps from 1/30 to 1/960 s, at zero and perturbed controls, to 1e-6 on every checked sample.
TEST(CapeSystem, GradcheckWithBodyAndSelfContactsAtEveryStepAndPerturbation) {
  for (int substeps : {1, 2, 8, 32}) {
    std::string text = cape_scene(5, 5, 0.12, "[[0, 0], [3, 0.4]]", 3, substeps);
    text.replace(text.find("[-0.215, -0.03, -0.3]"), 21, "[-0.215, -0.03, -0.24]");
    text.replace(text.find(R"("cg_tolerance")"), 0, R"("solver": "direct", )");
    text.insert(text.rfind('}'), R"(, "controls": {"kind": "per_frame", "alpha": 1e-4},
      "objectives": [{"type": "center_of_mass", "frame": 3, "weight": 100, "target": [0, 0.1, -0.2]}])");
    const Scene scene = parse_scene(text, "cape-gradcheck.json");
    auto sys = make_system(scene);
    Problem problem(scene, scene.time, *sys);
    test::gradcheck_perturbed(problem, 1e-4, {0.0, 0.01, 0.1}, [&](double perturb, const GradcheckResult& r) {
      const auto stats = sys->run_stats();
      std::printf("h = 1/%d, perturb %g: max_rel_error %.2e, fd_spread %.2e, %d checked, %d kinks, %g body, %g "
                  "self contacts\n",
                  30 * substeps, perturb, r.max_rel_error, r.fd_spread, r.checked, r.kinks, stats[0].second,
                  stats[1].second);
      EXPECT_GT(stats[0].second, 0) << "no body contact: the check would not cover it";
      EXPECT_GT(stats[1].second, 0) << "no self contact: the check would not cover it";
      EXPECT_GE(r.checked, 14) << "h = 1/" << 30 * substeps << " perturb " << perturb;
      EXPECT_LE(r.max_rel_error, 1e-6) << "h = 1/" << 30 * substeps << " perturb " << perturb;
    });
  }
}

// The shipped source scene builds and its first steps run with the cape in contact with the body but no
// particle deeper inside it than the contact layer's thickness.
TEST(CapeSystem, ShippedClipSceneSteps) {
  const Scene scene = load_scene(std::filesystem::path(KEYFRAME_SOURCE_DIR) / "scenes/cape-a.json");
  ASSERT_TRUE(scene.character.has_value());
  auto sys = make_system(scene);
  EXPECT_EQ(sys->particles(), 16 * 26);
  VecX x0, v0;
  sys->initial_state(x0, v0);
  Rollout r;
  ASSERT_TRUE(simulate(*sys, x0, v0, std::vector<VecX>(8, VecX::Zero(sys->dof())), r));
  EXPECT_TRUE(r.x.back().allFinite());
  double body_contacts = 0, min_distance = NAN;
  for (const auto& [name, value] : sys->run_stats()) {
    if (name == "body_contacts") body_contacts = value;
    if (name == "min_body_distance") min_distance = value;
  }
  std::printf("cape-a, 8 steps: %g body contacts, min body distance %.4g m\n", body_contacts, min_distance);
  EXPECT_GT(body_contacts, 0);  // the cape rests on the shoulders
  ASSERT_TRUE(std::isfinite(min_distance)) << "no contact query saw a particle";
  EXPECT_GT(min_distance, -scene.character->body_thickness);
}

}  // namespace
}  // namespace kf

// The shape keyframe's coverage term, which reads only the agents near each region sample, against the
// soft minimum over every agent: the same value and gradient to round-off over dense, sparse and clustered
// flocks; and the flock's adjoint gradient with coverage on against central differences at two step sizes,
// at perturbed controls.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "core/ground_region.h"
#include "opt/gradcheck.h"
#include "opt/objective_terms.h"
#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/make_system.h"
#include "../sim/gradient_test_helpers.h"

namespace kf {
namespace {

// ½w_c Σ_j (2r max(0, √D_j − r))², D_j the soft minimum over every agent (each sample against all agents);
// adds its gradient to gx. `uncovered` counts the samples with no agent within r.
double coverage_over_all_agents(const ShapeKeyframe& k, const VecX& x, VecX& gx, int& uncovered) {
  const int p = int(x.size() / 3);
  const double r2 = k.coverage_radius * k.coverage_radius, tau = r2 / 16;
  std::vector<double> d2(p);
  long double val = 0;
  uncovered = 0;
  for (const Vec2& q : region_samples(GroundRegion(k.polygon, k.holes), k.coverage_spacing)) {
    double nearest = std::numeric_limits<double>::infinity();
    for (int i = 0; i < p; ++i) {
      d2[i] = Vec2(x[3 * i] - q.x(), x[3 * i + 2] - q.y()).squaredNorm();
      nearest = std::min(nearest, d2[i]);
    }
    if (nearest - r2 <= 0) continue;
    ++uncovered;
    double sum = 0;
    for (int i = 0; i < p; ++i) sum += std::exp(-(d2[i] - nearest) / tau);
    const double soft = nearest - tau * std::log(sum);
    if (soft <= r2) continue;
    const double gap = std::sqrt(soft) - k.coverage_radius, scaled = 2 * k.coverage_radius * gap;
    for (int i = 0; i < p; ++i) {  // ∂/∂x_i of ½w (2r gap)², gap = √D − r
      const double c = k.coverage_weight * scaled * 2 * k.coverage_radius / (2 * std::sqrt(soft)) *
                       std::exp(-(d2[i] - nearest) / tau) / sum * 2;
      gx[3 * i] += c * (x[3 * i] - q.x());
      gx[3 * i + 2] += c * (x[3 * i + 2] - q.y());
    }
    val += 0.5 * k.coverage_weight * scaled * scaled;
  }
  return double(val);
}

// A 30 m square, coverage within 1.5 m sampled every 0.75 m (1,600 samples): the crowd figure's setting.
ShapeKeyframe square_to_cover() {
  ShapeKeyframe k;
  k.polygon = {Vec2(-15, -15), Vec2(15, -15), Vec2(15, 15), Vec2(-15, 15)};
  k.margin = 0.4;
  k.coverage_weight = 0.3;
  k.coverage_radius = 1.5;
  k.coverage_spacing = 0.75;
  return k;
}

// Dense: 1,600 agents over the square with a 9 m corner left empty. Sparse: 60 agents over a wider square.
// Clustered: 1,500 agents in a clump (every seventh on the one before it) and a few far strays.
VecX flock(const std::string& kind, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> clump(0, 0.5);
  const int p = kind == "dense" ? 1600 : kind == "sparse" ? 60 : 1500;
  VecX x = VecX::Zero(3 * p);
  for (int i = 0; i < p; ++i) {
    if (kind == "dense") {
      do x[3 * i] = 15 * u(rng), x[3 * i + 2] = 15 * u(rng);
      while (x[3 * i] > 6 && x[3 * i + 2] > 6);
    }
    if (kind == "sparse") x[3 * i] = 20 * u(rng), x[3 * i + 2] = 20 * u(rng);
    if (kind == "clustered") {
      x[3 * i] = 8 + clump(rng), x[3 * i + 2] = -6 + clump(rng);
      if (i % 7 == 0 && i > 0) x[3 * i] = x[3 * (i - 1)], x[3 * i + 2] = x[3 * (i - 1) + 2];
      if (i % 100 == 0) x[3 * i] = 60 * u(rng), x[3 * i + 2] = 60 * u(rng);
    }
    x[3 * i + 1] = u(rng);  // height: not read
  }
  return x;
}

TEST(ShapeCoverage, NearbyAgentsGiveTheValueAndGradientOfEveryAgent) {
  std::mt19937_64 rng(35);
  const ShapeKeyframe k = square_to_cover();
  ShapeKeyframe inside_only = k;
  inside_only.coverage_weight = 0;
  for (const std::string kind : {"dense", "sparse", "clustered"}) {
    const VecX x = flock(kind, rng), v = VecX::Zero(x.size());
    const int p = int(x.size() / 3);
    ObjectiveSpec spec, inside_spec;
    spec.kind = k, inside_spec.kind = inside_only;
    spec.frame = inside_spec.frame = 1;
    spec.weight = inside_spec.weight = 1.0;
    auto term = make_objective_term(spec, p), inside_term = make_objective_term(inside_spec, p);
    VecX gx = VecX::Zero(3 * p), gv = gx, ref_gx = gx, ref_gv = gx;
    const double val = term->eval(x, v, gx, gv);
    int uncovered = 0;
    const double ref_coverage = coverage_over_all_agents(k, x, ref_gx, uncovered);
    const double ref = inside_term->eval(x, v, ref_gx, ref_gv) + ref_coverage;
    std::printf("%s: %d agents, %d uncovered samples, coverage %.6g of %.6g, |value - all agents| %.2g, "
                "|gradient - all agents| / |gradient| %.2g\n",
                kind.c_str(), p, uncovered, ref_coverage, ref, std::abs(val - ref),
                (gx - ref_gx).norm() / ref_gx.norm());
    ASSERT_GT(uncovered, 10) << kind;
    ASSERT_GT(ref_coverage, 0.1 * (ref - ref_coverage)) << kind << ": the coverage must weigh in the value";
    EXPECT_LE(std::abs(val - ref), 1e-12 * std::abs(ref)) << kind;
    EXPECT_LE((gx - ref_gx).norm(), 1e-12 * ref_gx.norm()) << kind;
    EXPECT_EQ(gv.norm(), 0.0);
    // The same again: the term reuses its buffers and gives the same bits.
    VecX gx2 = VecX::Zero(3 * p), gv2 = gx2;
    EXPECT_EQ(term->eval(x, v, gx2, gv2), val);
    EXPECT_EQ(gx2, gx);
  }
}

// 40 agents whose spawn disc covers a third of a square and reaches past its near edge: the coverage term pulls
// at many samples, the inside term at the agents outside.
Scene covering_flock(double coverage_weight) {
  return parse_scene(R"({"seed": 3, "time": {"fps": 15, "substeps": 2, "frames": 8},
      "flock": {"agents": 40, "spawn": {"center": [0, 0, 0], "radius": 3.5, "velocity": [0, 0, 1.0]}},
      "objectives": [{"type": "shape", "frame": 8, "weight": 1, "margin": 0.3,
                      "polygon": [[-5, -1], [5, -1], [5, 9], [-5, 9]],
                      "coverage": {"weight": )" + std::to_string(coverage_weight) +
                         R"(, "radius": 1.2, "spacing": 0.6}}]})",
                     "coverage.json");
}

TEST(ShapeCoverage, FlockAdjointGradientMatchesFiniteDifferencesAtTwoSteps) {
  const Scene scene = covering_flock(2.0), without = covering_flock(0.0);
  auto sys = make_system(scene), sys_without = make_system(without);
  Problem problem(scene, scene.time, *sys), problem_without(without, without.time, *sys_without);
  // The coverage term weighs in: φ and its gradient at the initial controls differ from the term without it.
  VecX g, g_without;
  const VecX z = problem.initial_guess();
  const double phi = problem.evaluate(z, &g), phi_without = problem_without.evaluate(z, &g_without);
  std::printf("phi %.6g (without coverage %.6g), |grad - grad without| / |grad| %.3g\n", phi, phi_without,
              (g - g_without).norm() / g.norm());
  ASSERT_GT(phi_without, 0.0);
  ASSERT_GT(phi - phi_without, 0.2 * phi);
  ASSERT_GT((g - g_without).norm(), 0.2 * g.norm());
  for (double perturb : {0.0, 0.3}) {
    double rel[2];
    const double steps[2] = {3e-3, 1e-3};
    for (int h = 0; h < 2; ++h)
      test::gradcheck_perturbed(problem, steps[h], {perturb}, [&](double, const GradcheckResult& r) {
        std::printf("perturb %.1f eps %.0e: phi %.6g, |grad| %.3g, checked %d, kinks %d, max rel error %.2g, "
                    "cosine %.15f, spread %.2g\n",
                    perturb, steps[h], r.phi, r.grad_norm, r.checked, r.kinks, r.max_rel_error, r.cosine, r.fd_spread);
        ASSERT_GT(r.grad_norm, 1e-3);
        EXPECT_EQ(r.kinks, 0);
        EXPECT_GE(r.checked, 12);
        EXPECT_LT(r.max_rel_error, 1e-6);
        rel[h] = r.max_rel_error;
      });
    EXPECT_LT(std::abs(rel[0] - rel[1]), 1e-6) << "the two step sizes disagree";
  }
}

}  // namespace
}  // namespace kf

// The flock figures (paper figs. 1-3) in reduced form: optimised through Problem + minimize and judged by
// figure_measures; and the adjoint gradient of every figure scene against finite differences.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "opt/gradcheck.h"
#include "report/figure_measures.h"
#include "opt/objective_terms.h"
#include "opt/optimizer.h"
#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/make_system.h"

namespace kf {
namespace {

// One state per frame of the last evaluated rollout.
Trajectory frames_of(const Problem& problem, int particles) {
  Trajectory t;
  t.particles = particles;
  t.fps = problem.time().fps;
  for (int n = 0; n <= problem.time().steps(); n += problem.time().substeps) {
    t.x.push_back(problem.rollout().x[n]);
    t.v.push_back(problem.rollout().v[n]);
  }
  return t;
}

struct Optimised {
  OptimizeResult result;
  nlohmann::json measures;
};

// Optimises the scene as `keyframe optimize` does and measures the converged run.
Optimised optimise(const Scene& scene) {
  auto sys = make_system(scene, scene.time.h());
  Problem problem(scene, scene.time, *sys);
  Optimised o;
  o.result = minimize(problem, scene.optimizer, problem.initial_guess());
  problem.evaluate(o.result.z, nullptr);
  EXPECT_FALSE(problem.last_diverged());
  o.measures = figure_measures(scene, frames_of(problem, sys->particles()));
  return o;
}

const char* kForces = R"("avoidance": {"strength": 6, "radius": 1.5},
    "matching": {"strength": 0.5, "radius": 2.5}, "centering": {"strength": 1.0, "radius": 2.5})";

TEST(FlockFigures, SquareThenCrossReduced) {
  // 50 agents: a 7 m square at frame 15, then a cross of about the same area at frame 30.
  const Scene scene = parse_scene(R"({
    "seed": 2, "time": {"fps": 10, "substeps": 2, "frames": 30},
    "flock": {"agents": 50, )" + std::string(kForces) + R"(,
              "spawn": {"radius": 4.2, "velocity": [0, 0, 1.5]}},
    "objectives": [
      {"type": "shape", "frame": 15, "margin": 0.3, "coverage": {"weight": 0.3},
       "polygon": [[-3.5, 1], [3.5, 1], [3.5, 8], [-3.5, 8]]},
      {"type": "shape", "frame": 30, "margin": 0.3, "coverage": {"weight": 0.3},
       "polygon": [[-1.5, 3], [1.5, 3], [1.5, 6.5], [5, 6.5],
        [5, 9.5], [1.5, 9.5], [1.5, 13], [-1.5, 13], [-1.5, 9.5], [-5, 9.5], [-5, 6.5], [-1.5, 6.5]]}],
    "controls": {"kind": "per_frame", "alpha": 0.01},
    "optimizer": {"max_evaluations": 200, "ftol_rel": 1e-7}})",
                                  "square-cross.json");
  const Optimised o = optimise(scene);
  ASSERT_EQ(o.measures.size(), 2u);
  for (const auto& m : o.measures) {
    SCOPED_TRACE(m.dump());
    EXPECT_GE(m["inside_fraction"].get<double>(), 0.98);
    EXPECT_GE(m["coverage_fraction"].get<double>(), 0.95);  // the whole shape filled, not a clump in it
    EXPECT_GT(m["min_spacing"].get<double>(), 0.3);  // no clumps
    EXPECT_GT(m["median_spacing"].get<double>(), 0.6);
  }
}

TEST(FlockFigures, PathReduced) {
  // 30 agents, centre-of-mass keyframes every second along a bend.
  const Scene scene = parse_scene(R"({
    "seed": 3, "time": {"fps": 10, "substeps": 2, "frames": 40},
    "flock": {"agents": 30, )" + std::string(kForces) + R"(,
              "spawn": {"radius": 3.5, "velocity": [0, 0, 1.5]}},
    "objectives": [
      {"type": "center_of_mass", "frame": 10, "weight": 10, "target": [1.5, 0, 2]},
      {"type": "center_of_mass", "frame": 20, "weight": 10, "target": [3.5, 0, 3.5]},
      {"type": "center_of_mass", "frame": 30, "weight": 10, "target": [4.5, 0, 6]},
      {"type": "center_of_mass", "frame": 40, "weight": 10, "target": [3.5, 0, 8.5]}],
    "controls": {"kind": "per_frame", "alpha": 0.01},
    "optimizer": {"max_evaluations": 150, "ftol_rel": 1e-8}})",
                                  "path.json");
  const Optimised o = optimise(scene);
  for (const auto& m : o.measures) {
    SCOPED_TRACE(m.dump());
    EXPECT_LE(m["error_over_path"].get<double>(), 0.02);
  }
}

// The agent furthest back along +z at the start of a scene's flock.
int last_along_z(const Scene& scene) {
  auto sys = make_system(scene, scene.time.h());
  VecX x, v;
  sys->initial_state(x, v);
  int last = 0;
  for (int i = 1; i < sys->particles(); ++i)
    if (x[3 * i + 2] < x[3 * last + 2]) last = i;
  return last;
}

TEST(FlockFigures, RaceReduced) {
  // 20 agents heading along +z; the rearmost must finish in front while the flock's centre keeps to x = 0.
  const std::string head = R"({
    "seed": 4, "time": {"fps": 10, "substeps": 2, "frames": 40},
    "flock": {"agents": 20, )" + std::string(kForces) + R"(,
              "spawn": {"radius": 3, "velocity": [0, 0, 1.5]}},
    "controls": {"kind": "per_frame", "alpha": 0.01},
    "optimizer": {"max_evaluations": 150, "ftol_rel": 1e-8},)";
  const int runner = last_along_z(parse_scene(head + R"("objectives": []})", "race.json"));
  std::string others;  // the rest of the flock: kept together in a filled region just behind the racer
  for (int i = 0; i < 20; ++i)
    if (i != runner) others += (others.empty() ? "" : ", ") + std::to_string(i);
  const Scene scene = parse_scene(head + R"("objectives": [
      {"type": "center_of_mass", "frame": 20, "weight": 10, "target": [0, 0, 2.5]},
      {"type": "center_of_mass", "frame": 40, "weight": 10, "target": [0, 0, 5]},
      {"type": "position", "frame": 40, "weight": 10, "particles": [)" + std::to_string(runner) +
                                      R"(], "targets": [[0, 0, 9.3]]},
      {"type": "shape", "frame": 40, "weight": 10, "particles": [)" + others + R"(],
       "polygon": [[-3, 2], [3, 2], [3, 8], [-3, 8]], "coverage": {"weight": 0.3, "radius": 2}}]})",
                                  "race.json");
  const Optimised o = optimise(scene);
  const auto& race = o.measures[2];
  SCOPED_TRACE(o.measures.dump());
  EXPECT_TRUE(race["last_at_start"].get<bool>());
  EXPECT_TRUE(race["first_at_end"].get<bool>());
  EXPECT_EQ(race["racer_rank"], 1);
  EXPECT_TRUE(race["racer_within_front"].get<bool>()) << "the racer left the flock behind";
  EXPECT_TRUE(race["flock_connected"].get<bool>()) << "the flock split";
  EXPECT_LT(std::abs(o.measures[1]["error"].get<double>()), 0.3);  // the flock kept its straight path
}

GradcheckResult check_gradient(const Scene& scene, double perturb, int samples) {
  auto sys = make_system(scene, scene.time.h());
  Problem problem(scene, scene.time, *sys);
  VecX z = problem.initial_guess();
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal(0.0, perturb);
  for (int i = 0; i < z.size(); ++i) z[i] += normal(rng);
  return gradcheck(problem, z, {.samples = samples, .eps = 0.1, .kink_tolerance = 1e300, .seed = 5});
}

class FigureSceneGradient : public ::testing::TestWithParam<std::string> {};

TEST_P(FigureSceneGradient, AdjointMatchesFiniteDifferences) {
  const Scene scene = shortened(load_scene(KEYFRAME_SOURCE_DIR "/scenes/" + GetParam()), 6);
  const GradcheckResult r = check_gradient(scene, 0.5, 24);
  ASSERT_GT(r.grad_norm, 1e-6) << "the gradient is zero: nothing checked";
  EXPECT_GE(r.checked, 10);
  // The flock adjoint is exact: agreement is limited only by the finite differences, which on these large
  // objectives (φ ~ 1e3..1e4 at the shortened keyframes) need gradcheck's extrapolation and its account of
  // φ's round-off.
  EXPECT_GT(r.cosine, 1 - 1e-12) << r.to_json().dump();
  EXPECT_LT(r.rel_error_norm, 1e-7) << r.to_json().dump();
  EXPECT_LE(r.max_rel_error, 1e-6) << r.to_json().dump();
}

INSTANTIATE_TEST_SUITE_P(Scenes, FigureSceneGradient,
                         ::testing::Values("square.json", "cross.json", "path.json", "race.json",
                                           "square-1000.json"),
                         [](const auto& info) {
                           std::string s = info.param.substr(0, info.param.find('.'));
                           std::replace(s.begin(), s.end(), '-', '_');
                           return s;
                         });

TEST(FlockFigures, GradientOfTwentyAgentsOverSixtySteps) {
  // Every force on, a shape with a margin (agents on both sides of it), a centre of mass and a runner.
  const Scene scene = parse_scene(R"({
    "seed": 5, "time": {"fps": 10, "substeps": 3, "frames": 20},
    "flock": {"agents": 20, "spawn": {"radius": 3, "velocity": [0.5, 0, 1.2]}},
    "objectives": [
      {"type": "shape", "frame": 10, "margin": 0.5, "weight": 2, "polygon": [[-2, 0], [2, 0], [2, 4], [-2, 4]]},
      {"type": "center_of_mass", "frame": 15, "target": [1, 0, 4]},
      {"type": "position", "frame": 20, "particles": [3], "targets": [[0, 0, 6]]}],
    "controls": {"kind": "per_step", "alpha": 0.01}})",
                                  "twenty.json");
  ASSERT_EQ(scene.time.steps(), 60);
  const GradcheckResult r = check_gradient(scene, 0.5, 40);
  ASSERT_GT(r.grad_norm, 1e-6);
  EXPECT_LE(r.max_rel_error, 1e-6) << r.to_json().dump();
  EXPECT_GT(r.cosine, 1 - 1e-10);
}

TEST(ShapeTerm, MarginGradientMatchesFiniteDifferencesInsideAndOutside) {
  ShapeKeyframe shape;
  shape.margin = 0.4;
  shape.polygon = {{-1, 0}, {1, 0}, {1, 1}, {3, 1}, {3, 2}, {1, 2}, {1, 3}, {-1, 3}};  // an L-ish concave region
  ObjectiveSpec s{.kind = shape, .frame = 1, .weight = 1.5};
  // Agents far outside, just outside, just inside (within the margin) and deep inside.
  const std::vector<Vec2> at = {{-2.5, 1.2}, {1.1, 0.5}, {0.8, 2.6}, {2.5, 1.2}, {0, 1.5}, {4, 3}, {1.3, 2.2}};
  const int p = int(at.size());
  VecX x = VecX::Zero(3 * p), v = VecX::Zero(3 * p);
  for (int i = 0; i < p; ++i) x[3 * i] = at[i].x(), x[3 * i + 2] = at[i].y();
  auto term = make_objective_term(s, p);
  VecX gx = VecX::Zero(3 * p), gv = gx;
  const double val = term->eval(x, v, gx, gv);
  ASSERT_GT(val, 0);
  ASSERT_GT(gx.norm(), 0);
  EXPECT_EQ(gx.segment<3>(3 * 4).norm(), 0.0);  // deep inside: no pull
  EXPECT_GT(gx.segment<3>(3 * 2).norm(), 0.0);  // inside but within the margin: pulled in
  const double eps = 1e-6, floor = 1e-6 * gx.cwiseAbs().maxCoeff();
  for (int k = 0; k < 3 * p; ++k) {
    VecX e = VecX::Zero(3 * p), g1 = gx, g2 = gx;
    e[k] = eps;
    const double fd = (term->eval(x + e, v, g1, g2) - term->eval(x - e, v, g1, g2)) / (2 * eps);
    EXPECT_LE(std::abs(fd - gx[k]) / std::max(std::abs(fd), floor), 1e-6) << "component " << k;
  }
  // Margin 0 is exactly the plain outside-only term.
  std::get<ShapeKeyframe>(s.kind).margin = 0;
  auto plain = make_objective_term(s, p);
  VecX g0 = VecX::Zero(3 * p);
  // By hand: squared distances to the region 1.5², 0.1², 0, 0, 0, (1² + 1²) to the corner (3, 2), 0.2².
  const double expect = 0.5 * 1.5 * (2.25 + 0.01 + 2.0 + 0.04);
  EXPECT_NEAR(plain->eval(x, v, g0, gv), expect, 1e-12);
}

}  // namespace
}  // namespace kf

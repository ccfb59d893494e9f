// The cloth figures (arch, shapes, ring toss) on reduced versions of their scenes: each is optimised through
// Problem + minimize and judged by figure_measures, as `keyframe optimize` does for the full scenes.
// Also the approximate adjoint on scenes/cloth-gradcheck.json (6x6 cloth, 40 steps) at the scene's step.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>

#include "app/optimize_job.h"
#include "opt/gradcheck.h"
#include "report/collider_measures.h"
#include "report/figure_measures.h"
#include "opt/optimizer.h"
#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/make_system.h"

namespace kf {
namespace {

using nlohmann::json;

struct Outcome {
  double phi0 = 0;
  OptimizeResult result;
  json measures;
};

// Optimises the scene and measures the best point's frames.
Outcome optimise(const Scene& scene) {
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  Outcome out;
  const VecX z0 = problem.initial_guess();
  out.phi0 = problem.evaluate(z0, nullptr);
  out.result = minimize(problem, scene.optimizer, z0);
  problem.evaluate(out.result.z, nullptr);
  EXPECT_FALSE(problem.last_diverged());
  Trajectory t;
  t.particles = sys->particles();
  t.fps = scene.time.fps;
  for (int f = 0; f <= scene.time.frames; ++f) {
    t.x.push_back(problem.rollout().x[f * scene.time.substeps]);
    t.v.push_back(problem.rollout().v[f * scene.time.substeps]);
  }
  out.measures = figure_measures(scene, t);
  return out;
}

TEST(ClothFigures, ArchReachesTheCylinderWithinOnePercentOfTheWidth) {
  // Weightless and in free space, as scenes/arch.json; h = 1/120 s, where the approximate adjoint is
  // accurate enough for the line search to keep making progress (at 1/30 it stalls near 2 %).
  const Scene scene = parse_scene(R"({
    "time": {"fps": 30, "substeps": 4, "frames": 20},
    "cloth": {"nx": 10, "ny": 10, "width": 1.0, "height": 1.0, "origin": [-0.5, 0, -0.5],
              "u_axis": [1, 0, 0], "v_axis": [0, 0, 1], "mass": 0.5, "gravity": [0, 0, 0], "cg_tolerance": 1e-10},
    "objectives": [{"type": "arch", "frame": 20, "weight": 100, "axis_point": [0, -0.2, 0], "axis": [0, 0, 1],
                    "radius": 0.45}],
    "controls": {"kind": "per_frame", "alpha": 1e-5},
    "optimizer": {"max_evaluations": 20, "ftol_rel": 1e-10}})",
                                  "arch-small.json");
  const Outcome o = optimise(scene);
  const json& m = o.measures.at(0);
  ASSERT_EQ(m.at("type"), "arch");
  std::printf("arch 10x10: %d evaluations, phi %.3g -> %.3g, %s\n", o.result.evaluations, o.phi0, o.result.phi,
              m.dump().c_str());
  EXPECT_LE(m.at("rms_over_width").get<double>(), 0.01) << o.result.status << " after " << o.result.evaluations;
  EXPECT_LT(o.result.phi, 1e-3 * o.phi0);
}

TEST(ClothFigures, ShapesMatchBothPositionKeyframes) {
  // An 8x8 sheet hanging from its top edge: first swung out by 1 rad, then tilted back the other way.
  const int n = 8;
  const double d = 1.0 / (n - 1), top = 1.5;
  json flat = json::array(), tilt = json::array();
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = -0.5 + i * d, s = (n - 1 - j) * d;
      flat.push_back({x, top - s * std::cos(1.0), s * std::sin(1.0)});
      tilt.push_back({x, top - s * std::cos(0.5), -s * std::sin(0.5)});
    }
  json j = json::parse(R"({
    "time": {"fps": 30, "substeps": 2, "frames": 30},
    "cloth": {"nx": 8, "ny": 8, "width": 1.0, "height": 1.0, "origin": [-0.5, 0.5, 0], "mass": 0.3,
              "pins": "top_edge", "cg_tolerance": 1e-6},
    "controls": {"kind": "per_frame", "alpha": 1e-5},
    "optimizer": {"max_evaluations": 40, "ftol_rel": 1e-10}})");
  j["objectives"] = {{{"type", "position"}, {"frame", 15}, {"weight", 100}, {"targets", flat}},
                     {{"type", "position"}, {"frame", 30}, {"weight", 100}, {"targets", tilt}}};
  const Scene scene = parse_scene(j.dump(), "shapes-small.json");
  const Outcome o = optimise(scene);
  std::printf("shapes 8x8: %d evaluations, phi %.3g -> %.3g, %s\n", o.result.evaluations, o.phi0, o.result.phi,
              o.measures.dump().c_str());
  ASSERT_EQ(o.measures.size(), 2u);
  for (const json& m : o.measures) {
    ASSERT_EQ(m.at("type"), "position");
    EXPECT_LT(m.at("rms_over_width").get<double>(), 0.03) << m.dump();
  }
  EXPECT_LT(o.result.phi, 1e-2 * o.phi0);
}

TEST(ClothFigures, RingTossPassesThroughTheRingWithoutPenetrating) {
  // A 12x12 sheet thrown through a ring about the direction of the throw; only initial velocities change.
  // The scene's initial velocity misses the ring (too low), so the optimiser has to find the throw.
  const Scene scene = parse_scene(R"({
    "time": {"fps": 30, "substeps": 1, "frames": 20},
    "cloth": {"nx": 12, "ny": 12, "width": 0.4, "height": 0.4, "origin": [-1.4, 1.0, -0.2],
              "u_axis": [1, 0, 0], "v_axis": [0, 0, 1], "mass": 0.2, "velocity": [2.4, 1.5, 0],
              "cg_tolerance": 1e-6,
              "colliders": [{"type": "torus", "center": [0, 1.2, 0], "axis": [1, 0, 0], "radius": 0.3,
                             "tube_radius": 0.03, "thickness": 0.01, "stiffness": 1e3}]},
    "objectives": [{"type": "center_of_mass", "frame": 15, "weight": 100, "target": [0, 1.2, 0]}],
    "controls": {"kind": "initial_velocity", "alpha": 1e-6},
    "optimizer": {"max_evaluations": 40, "ftol_rel": 1e-10}})",
                                  "ring-toss-small.json");
  const Outcome o = optimise(scene);
  ASSERT_EQ(o.measures.size(), 3u);  // the keyframe, the sheet, the ring
  EXPECT_LT(o.measures.at(1).at("flip_degrees").get<double>(), 45.0);  // thrown, not turned over
  const json& ring = o.measures.at(2);
  ASSERT_EQ(ring.at("type"), "ring");
  EXPECT_TRUE(ring.at("through_ring").get<bool>()) << ring.dump();
  EXPECT_LT(ring.at("min_distance_to_ring_axis_when_crossing").get<double>(), 0.05) << ring.dump();
  EXPECT_GE(ring.at("min_signed_distance").get<double>(), 0.0) << ring.dump();
  EXPECT_LT(o.measures.at(0).at("error").get<double>(), 0.01);
}

// The measure object of `type` in a report's measures (the last one when there are several).
const json& measure(const json& report, const std::string& type) {
  const json* found = nullptr;
  for (const json& m : report.at("measures"))
    if (m.at("type") == type) found = &m;
  if (!found) throw std::runtime_error("no " + type + " measure in " + report.at("measures").dump());
  return *found;
}

TEST(ClothFigures, RingTossTurnsOverThroughTheRingAndLandsBeyondIt) {
  // tests/figures/ring-toss-small.json, written by scripts/make_ring_toss.py beside scenes/ring-toss.json: a
  // 12x12 sheet, the full scene's keyframes (a roll that turns it over) and its default plan -- the throw
  // fitted to the keyframes among searched ones, the rigid throw, a lattice of velocities, then one velocity
  // per particle -- through `keyframe optimize`'s own job.
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("keyframe_ring_toss_" + std::to_string(getpid()));
  fs::remove_all(dir);
  OptimizeOptions opt;
  opt.out = dir.string();
  opt.quiet = true;
  optimize_job(std::string(KEYFRAME_SOURCE_DIR) + "/tests/figures/ring-toss-small.json", opt);
  std::ifstream in(dir / "report.json");
  const json report = json::parse(in);
  EXPECT_EQ(report.at("controls"), "initial_velocity");
  EXPECT_EQ(report.at("control_variables").get<int>(), 3 * 12 * 12);
  EXPECT_EQ(report.at("stages").get<int>(), 3);
  EXPECT_LT(report.at("final_objective").get<double>(),
            1e-3 * report.at("throw_search").at("start_objective").get<double>());  // the scene's own throw
  for (const json& k : report.at("keyframe_errors")) EXPECT_TRUE(k.at("met").get<bool>()) << k.dump();
  const json& ring = measure(report, "ring");
  EXPECT_TRUE(ring.at("through_ring").get<bool>()) << ring.dump();
  EXPECT_TRUE(ring.at("penetration_free").get<bool>()) << ring.dump();
  EXPECT_GT(ring.at("end_beyond_ring_plane").get<double>(), 0.0) << ring.dump();
  const json& sheet = measure(report, "sheet");
  EXPECT_GE(sheet.at("flip_degrees").get<double>(), 150.0) << sheet.dump();
  const json& ground = measure(report, "ground");
  EXPECT_TRUE(ground.at("on_ground_at_end").get<bool>()) << ground.dump();
  // On this sheet the per-particle stage lowers the keyframe error of the rigid throw (iterations.csv: phi,
  // its "effort" column, and the stage of each evaluation; the stages' efforts measure different things, so
  // they are left out).
  std::ifstream csv(dir / "iterations.csv");
  auto cells_of = [](const std::string& line) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string c; std::getline(row, c, ',');) cells.push_back(c);
    return cells;
  };
  std::string line;
  std::getline(csv, line);
  const std::vector<std::string> header = cells_of(line);
  const auto column = [&](const std::string& name) {
    return int(std::find(header.begin(), header.end(), name) - header.begin());
  };
  const int phi_col = column("phi"), stage_col = column("stage"), effort_col = column("effort");
  ASSERT_LT(effort_col, int(header.size())) << line;
  double best[3] = {INFINITY, INFINITY, INFINITY};
  while (std::getline(csv, line)) {
    const std::vector<std::string> cells = cells_of(line);
    ASSERT_EQ(cells.size(), header.size()) << line;
    const int stage = std::stoi(cells[size_t(stage_col)]);
    ASSERT_TRUE(stage >= 1 && stage <= 3) << line;
    const double keyframes = std::stod(cells[size_t(phi_col)]) - std::stod(cells[size_t(effort_col)]);
    if (std::isfinite(keyframes)) best[stage - 1] = std::min(best[stage - 1], keyframes);
  }
  EXPECT_LT(best[2], 0.75 * best[0]) << "keyframe terms: rigid stage " << best[0] << ", per-particle stage " << best[2];
  if (!HasFailure()) fs::remove_all(dir);
}

TEST(ClothFigures, SheetMeasureSeesAHalfTurn) {
  // A free 2x2 sheet in the x-z plane, rolled about x by 0, 90, 180 and then 120 degrees.
  const Scene scene = parse_scene(R"({"time": {"frames": 3}, "cloth": {"nx": 2, "ny": 2, "width": 1, "height": 1,
    "u_axis": [1, 0, 0], "v_axis": [0, 0, 1]}})", "sheet.json");
  Trajectory t;
  t.particles = 4;
  for (double deg : {0.0, 90.0, 180.0, 120.0}) {
    const double a = deg * M_PI / 180;
    VecX x(12), v = VecX::Zero(12);
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) seg(x, 2 * j + i) = Vec3(i, -j * std::sin(a), j * std::cos(a));
    t.x.push_back(x);
    t.v.push_back(v);
  }
  const json m = figure_measures(scene, t);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].at("type"), "sheet");
  EXPECT_NEAR(m[0].at("flip_degrees").get<double>(), 180.0, 1e-9);
  EXPECT_NEAR(m[0].at("flip_degrees_at_end").get<double>(), 120.0, 1e-9);
}

TEST(ClothFigures, RingMeasuresSeeAMissAndAPenetration) {
  // Two hand-made frames: a single particle crosses the ring's plane inside the tube, then near the axis.
  TorusShape torus;
  torus.axis = Vec3::UnitX();
  torus.radius = 0.3;
  torus.tube_radius = 0.03;
  Trajectory t;
  t.particles = 1;
  t.x = {Vec3(-0.01, 0.3, 0), Vec3(0.01, 0.3, 0)};
  t.v = t.x;
  json m = ring_measures(torus, t);
  EXPECT_EQ(m.at("crossings"), 1);
  EXPECT_FALSE(m.at("through_ring").get<bool>());
  EXPECT_NEAR(m.at("min_distance_to_ring_axis_when_crossing").get<double>(), 0.3, 1e-12);
  EXPECT_LT(m.at("min_signed_distance").get<double>(), 0.0);
  EXPECT_FALSE(m.at("penetration_free").get<bool>());
  t.x = {Vec3(-0.01, 0.05, 0), Vec3(0.01, 0.05, 0)};
  m = ring_measures(torus, t);
  EXPECT_TRUE(m.at("through_ring").get<bool>());
  EXPECT_TRUE(m.at("penetration_free").get<bool>());
  EXPECT_GT(m.at("end_beyond_ring_plane").get<double>(), 0.0);
  // Outside the tube at both frames, but the straight path between them runs through its core.
  t.x = {Vec3(-0.1, 0.3, 0), Vec3(0.1, 0.3, 0)};
  m = ring_measures(torus, t);
  EXPECT_GT(m.at("min_signed_distance").get<double>(), 0.0);
  EXPECT_NEAR(m.at("min_signed_distance_between_frames").get<double>(), -0.03, 1e-3);
  EXPECT_FALSE(m.at("penetration_free").get<bool>());
  // The same jump beside the tube (0.05 from its core) stays free.
  t.x = {Vec3(-0.1, 0.22, 0), Vec3(0.1, 0.22, 0)};
  m = ring_measures(torus, t);
  EXPECT_NEAR(m.at("min_signed_distance_between_frames").get<double>(), 0.05, 1e-3);
  EXPECT_TRUE(m.at("penetration_free").get<bool>());
}

TEST(ClothFigures, GradcheckSceneAgreesWithFiniteDifferencesAtItsStep) {
  const Scene scene = load_scene(std::string(KEYFRAME_SOURCE_DIR) + "/scenes/cloth-gradcheck.json");
  ASSERT_EQ(scene.cloth->nx * scene.cloth->ny, 36);
  ASSERT_EQ(scene.time.steps(), 40);
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  VecX z = problem.initial_guess() + 0.01 * VecX::Random(problem.size());
  const GradcheckResult r = gradcheck(problem, z, {.samples = 40, .eps = 1e-4, .seed = 3});
  ASSERT_GT(r.grad_norm, 1e-6);
  EXPECT_GE(r.checked, 30);
  EXPECT_LT(r.max_rel_error, 1e-6) << "cosine " << r.cosine;
}

}  // namespace
}  // namespace kf

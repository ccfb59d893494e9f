// The reachable-by-construction scenes (bench/bench_reachable.h): the controls that copy the variant meet
// every keyframe through the optimiser's own problem, and the uncontrolled scene misses them.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <set>
#include <sstream>

#include "../sim/character_test_util.h"
#include "../support/reachable_classes.h"
#include "bench/bench_reachable.h"
#include "adjoint/rollout.h"
#include "core/error.h"
#include "opt/keyframe_residuals.h"
#include "opt/keyframes/keyframe_common.h"
#include "opt/problem.h"
#include "scene/scene.h"
#include "sim/make_system.h"

namespace kf {
namespace {

const std::filesystem::path kDir = std::filesystem::path(KEYFRAME_SOURCE_DIR) / "tests/results/reachable/scenes";

Scene parsed(const ReachableScene& r) { return parse_scene(r.scene.dump(), kDir / (r.name + ".json")); }

// The optimisation variables that copy the variant: its initial velocities, or its force in every block.
VecX variant_controls(const Scene& scene, Problem& problem, const ReachableVariant& variant) {
  const Controls& c = problem.controls();
  if (!c.forces()) return c.from_initial_velocity(variant_initial_velocity(scene, variant));
  const VecX u = variant_step_force(scene, variant);
  const bool planar = problem.system().planar();
  const int p = problem.system().particles(), nc = planar ? 2 : 3;
  const int comps[3] = {0, planar ? 2 : 1, 2};
  VecX z = VecX::Zero(problem.size());
  EXPECT_EQ(z.size() % (p * nc), 0);
  for (int b = 0; b < z.size() / (p * nc); ++b)
    for (int i = 0; i < p; ++i)
      for (int k = 0; k < nc; ++k) z(b * p * nc + i * nc + k) = u(3 * i + comps[k]);
  return z;
}

double keyframe_terms(const Problem& problem) {
  double s = 0;
  for (const auto& [name, value] : problem.breakdown())
    if (name != "effort") s += value;
  return s;
}

void expect_variant_controls_meet_the_keyframes(const std::string& kind) {
  for (int index = 0; index < 4; ++index) {
    SCOPED_TRACE(kind + "-" + std::to_string(index));
    const ReachableScene r = generate_reachable(kind, 52, index, true, kDir);
    const Scene scene = parsed(r);
    ASSERT_EQ(int(scene.objectives.size()), r.keyframes);
    auto sys = make_system(scene);
    Problem problem(scene, scene.time, *sys);
    problem.evaluate(problem.initial_guess(), nullptr);
    const double before = keyframe_terms(problem);
    problem.evaluate(variant_controls(scene, problem, r.variant), nullptr);
    const double after = keyframe_terms(problem);
    EXPECT_GT(before, 0);
    EXPECT_LT(after, 1e-10 * before) << "uncontrolled " << before;
  }
}

class ReachableClass : public testing::TestWithParam<std::string> {};
class ReachableCapeClass : public testing::TestWithParam<std::string> {};

TEST_P(ReachableClass, VariantControlsMeetEveryKeyframeTheUncontrolledSceneMisses) {
  expect_variant_controls_meet_the_keyframes(GetParam());
}
TEST_P(ReachableCapeClass, VariantControlsMeetEveryKeyframeTheUncontrolledSceneMisses) {
  expect_variant_controls_meet_the_keyframes(GetParam());
}

INSTANTIATE_TEST_SUITE_P(Generated, ReachableClass, testing::ValuesIn(test::reachable_classes_with_character(false)),
                         test::class_test_name);
INSTANTIATE_TEST_SUITE_P(Generated, ReachableCapeClass, testing::ValuesIn(test::reachable_classes_with_character(true)),
                         test::class_test_name);

// Forces m dg on every particle move a sheet as its gravity tilted by dg does (what the variant stands for).
void expect_forces_match_tilted_gravity(const std::vector<std::string>& kinds) {
  for (const std::string& kind : kinds) {
    SCOPED_TRACE(kind);
    const ReachableScene r = generate_reachable(kind, 52, 1, true, kDir);
    ASSERT_GT(r.variant.dg.norm(), 0.5);
    const Scene scene = parsed(r);
    const std::vector<VecX> forced = simulate_variant(scene, r.variant);
    Scene tilted = scene;
    tilted.cloth->gravity += r.variant.dg;
    const std::vector<VecX> fallen = simulate_variant(tilted, ReachableVariant{});
    ASSERT_EQ(forced.size(), fallen.size());
    const double moved = (forced.back() - forced.front()).cwiseAbs().maxCoeff();
    EXPECT_GT(moved, 0.01);
    EXPECT_LT((forced.back() - fallen.back()).cwiseAbs().maxCoeff(), 1e-6);
  }
}

TEST(ReachableScenes, ForcesOfTheTiltMatchATiltedGravity) {
  expect_forces_match_tilted_gravity({"hang-corners", "drop-collider", "hang-points"});
}
TEST(ReachableCapeScenes, ForcesOfTheTiltMatchATiltedGravity) { expect_forces_match_tilted_gravity({"cape", "cape-wuson"}); }

// The committed suite holds the shares the issue asks for: >= 100 scenes, >= 8 classes, >= 30 % with
// keyframes at two or three frames, >= 20 % friction, >= 20 % initial-velocity throws, >= 10 % on a
// character; and the generator still writes those files.
TEST(ReachableScenes, CommittedSuiteCoversItsShares) {
  const auto suite = reachable_suite(ReachableSweepOptions{});
  ASSERT_GE(suite.size(), 100u);
  std::set<std::string> classes;
  int multi = 0, friction = 0, thrown = 0, character = 0;
  for (const auto& [name, kind] : suite) {
    std::ifstream in(kDir / (name + ".json"));
    ASSERT_TRUE(in) << name;
    const nlohmann::json s = nlohmann::json::parse(in);
    classes.insert(kind);
    std::set<int> frames;
    for (const auto& k : s.at("objectives")) frames.insert(k.at("frame").get<int>());
    multi += frames.size() >= 2;
    bool rubs = false;
    if (s.contains("cloth") && s["cloth"].contains("colliders"))
      for (const auto& c : s["cloth"]["colliders"]) rubs |= c.value("friction", 0.0) > 0;
    friction += rubs;
    thrown += s.at("controls").at("kind") == "initial_velocity";
    character += s.contains("character");
  }
  const double n = double(suite.size());
  EXPECT_GE(classes.size(), 8u);
  EXPECT_GE(multi / n, 0.3);
  EXPECT_GE(friction / n, 0.2);
  EXPECT_GE(thrown / n, 0.2);
  EXPECT_GE(character / n, 0.1);
  for (const auto& [name, kind] : {suite[0], suite[13]}) {
    std::ifstream in(kDir / (name + ".json"));
    const ReachableScene r = generate_reachable(kind, ReachableSweepOptions{}.seed,
                                                std::stoi(name.substr(name.rfind('-') + 1)), false, kDir);
    EXPECT_EQ(r.scene, nlohmann::json::parse(in)) << name;
  }
}

// A scene name the suite does not hold is refused with one line before anything is written (a typo ran nothing
// and exited 0).
TEST(ReachableScenes, AnUnknownSceneNameIsRefusedBeforeAnythingIsWritten) {
  test::TempDir dir;
  ReachableSweepOptions o;
  o.scenes = {"throw-1", "throw-99"};
  o.scene_dir = dir.path() / "scenes";
  o.generate_only = true;
  try {
    bench_reachable(o, dir.path() / "out");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"throw-99\""), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(o.scene_dir));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out"));
}

// The poncho class stays out of the 100 (which it would otherwise reshuffle) and, named, gives `count` scenes;
// its keyframes name free vertices of the mesh (a side, a vertex, a few, or all), not grid indices.
TEST(ReachableCapeScenes, APonchoIsDrawnOnlyWhenNamedAndKeysFreeVerticesOfItsMesh) {
  for (const auto& [name, kind] : reachable_suite(ReachableSweepOptions{})) EXPECT_NE(kind, "poncho") << name;
  ReachableSweepOptions o;
  o.classes = {"poncho", "cape"};
  o.count = 8;
  int ponchos = 0;
  for (const auto& [name, kind] : reachable_suite(o)) ponchos += kind == "poncho";
  EXPECT_EQ(ponchos, 8);
  std::set<std::size_t> sizes;
  for (int index = 0; index < 8; ++index) {
    const ReachableScene r = generate_reachable("poncho", 52, index, true, kDir);
    const Scene scene = parsed(r);
    ASSERT_TRUE(scene.cloth && scene.cloth->mesh);
    EXPECT_EQ(r.particles, scene.cloth->mesh->particles());
    for (const ObjectiveSpec& k : scene.objectives) {
      sizes.insert(k.particles.size());
      for (int i : k.particles) {
        EXPECT_LT(i, r.particles);
        EXPECT_FALSE(std::binary_search(scene.cloth->pins.begin(), scene.cloth->pins.end(), i)) << r.name << " " << i;
      }
    }
  }
  EXPECT_GE(sizes.size(), 3u) << "the draws name particle sets of one or two sizes only";
}

// --reachable-well-conditioned: a drop whose keyframe a thousandth of its tilt moves 4.8 tolerances
// (drop-collider-8, conditioning/conditioning.csv) is drawn again until one is not; a hanging sheet that moves
// 0.01 tolerances is the very scene the suite holds.
TEST(ReachableScenes, AWellConditionedDrawReplacesAKnifeEdgeAndKeepsTheRest) {
  const unsigned seed = ReachableSweepOptions{}.seed;
  const ReachableScene hang = generate_reachable("hang-corners", seed, 0, false, kDir, true);
  EXPECT_EQ(hang.redraws, 0);
  EXPECT_GT(hang.conditioning, 0);
  EXPECT_LT(hang.conditioning, 0.1);
  EXPECT_EQ(hang.scene, generate_reachable("hang-corners", seed, 0, false, kDir).scene);
  const ReachableScene drop = generate_reachable("drop-collider", seed, 8, false, kDir, true);
  EXPECT_GE(drop.redraws, 1);
  EXPECT_GE(drop.conditioning, 0);
  EXPECT_LE(drop.conditioning, 1);
  EXPECT_NE(drop.scene, generate_reachable("drop-collider", seed, 8, false, kDir).scene);
  EXPECT_EQ(drop.name, "drop-collider-8");
}

// Not a check: how well conditioned each generated cloth scene's keyframes are, through the optimiser's own
// problem. The variant's change (dg, or dv and omega) is moved by a fraction eps of its own size
// (perturbed_variant: scaled by 1 +- eps, and turned eps off its direction two ways), and the keyframed particles' RMS displacement from the variant's own motion is measured in each
// keyframe's tolerance; the row keeps the largest over the four. A keyframe that a thousandth of the change
// moves by more than its tolerance is a knife edge: reachable, but from no neighbourhood a search can land in.
//   KEYFRAME_NO_FP_TRAPS=1 KEYFRAME_CONDITIONING_CSV=OUT.csv keyframe_tests
//     --gtest_also_run_disabled_tests --gtest_filter='ReachableScenes.DISABLED_Conditioning*'
//   (KEYFRAME_CONDITIONING_SCENES="throw-2 ..." for some)
TEST(ReachableScenes, DISABLED_ConditioningOfEveryClothScene) {
  const char* only = std::getenv("KEYFRAME_CONDITIONING_SCENES");
  const char* path = std::getenv("KEYFRAME_CONDITIONING_CSV");
  std::set<std::string> chosen;
  if (only) {
    std::istringstream in(only);
    for (std::string s; in >> s;) chosen.insert(s);
  }
  std::ofstream csv(path ? path : "conditioning.csv");
  csv << "scene,class,keyframes,eps,worst_displacement_tol\n";
  for (const auto& [name, kind] : reachable_suite(ReachableSweepOptions{})) {
    if (kind.rfind("flock", 0) == 0 || (only && !chosen.count(name))) continue;
    const ReachableScene r = generate_reachable(kind, ReachableSweepOptions{}.seed,
                                                std::stoi(name.substr(name.rfind('-') + 1)), false, kDir);
    const Scene scene = parsed(r);
    auto sys = make_system(scene);
    Problem problem(scene, scene.time, *sys);
    const std::vector<PlacedKeyframe> placed = placed_keyframes(problem, scene);
    const double tol = cloth_tolerance(scene);
    VecX r0(residual_count(placed)), r1(r0.size());
    problem.evaluate(variant_controls(scene, problem, r.variant), nullptr);
    keyframe_residuals(problem.rollout(), placed, false, r0);
    for (const double eps : {1e-3, 1e-4}) {
      double worst = 0;
      for (int how = 0; how < 4; ++how) {
        const ReachableVariant v = perturbed_variant(r.variant, eps, how);
        problem.evaluate(variant_controls(scene, problem, v), nullptr);
        keyframe_residuals(problem.rollout(), placed, false, r1);
        long row = 0;
        for (const PlacedKeyframe& k : placed) {
          const double moved = (r1 - r0).segment(row, k.rows()).norm() / std::sqrt(k.rows() / 3.0);
          worst = std::max(worst, moved / tol);
          row += k.rows();
        }
      }
      csv << name << ',' << kind << ',' << r.keyframes << ',' << eps << ',' << worst << '\n' << std::flush;
      std::cout << name << " eps " << eps << ": worst keyframe moved " << worst << " tolerances" << std::endl;
    }
  }
}

}  // namespace
}  // namespace kf

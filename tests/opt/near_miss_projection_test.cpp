// Gauss–Newton onto the keyframes for force controls (opt/keyframe_projection.h, opt/near_miss_projection.h):
// a target the controls reach exactly (a free sheet's centre of mass, a whole sheet moved as one) met in one or
// two Jacobians for per-frame, per-step and lattice forces; the residuals' adjoint rows for forces against
// central differences at two step sizes, at perturbed forces with the sheet on a sphere; the sketch of a
// whole-sheet keyframe's residuals.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>

#include "opt/keyframe_projection.h"
#include "opt/keyframe_residuals.h"
#include "opt/keyframes/keyframe_common.h"
#include "opt/near_miss_projection.h"
#include "opt/problem.h"
#include "opt/residual_sketch.h"
#include "scene/scene.h"
#include "sim/make_system.h"
#include "residual_flight_check.h"

namespace kf {
namespace {

// A 6 x 6 sheet falling freely (no drag): its centre of mass is linear in the forces, and a force the same on
// every particle moves every particle alike.
const std::string kFree = R"("time": {"fps": 30, "substeps": 2, "frames": 16}, "cloth": {"nx": 6, "ny": 6,
    "width": 0.4, "height": 0.4, "origin": [-0.2, 1.0, -0.2], "u_axis": [1, 0, 0], "v_axis": [0, 0, 1],
    "velocity": [0.5, 1, 0], "mass": 0.1, "air_drag": 0, "cg_tolerance": 1e-13})";

// A scene with controls of `kind`: per_frame_lattice (what a coarse stage optimises, not a scene file's
// kind) is set after parsing.
Scene scene_with(const std::string& text_before_kind, const std::string& kind, const std::string& after, const char* name) {
  const bool lattice = kind == "per_frame_lattice";
  Scene scene = parse_scene(text_before_kind + (lattice ? "per_frame" : kind) + after, name);
  if (lattice) scene.controls.kind = ControlKind::kPerFrameLattice;
  return scene;
}

std::string vec(const Vec3& v) {
  std::ostringstream os;
  os.precision(17);
  os << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return os.str();
}

// Where the uncontrolled sheet is at frame 16 (every particle).
VecX uncontrolled_at_end(const std::string& kind) {
  const Scene scene = scene_with("{" + kFree + R"(, "controls": {"kind": ")", kind,
                                 R"("}, "objectives": [{"type": "center_of_mass", "frame": 16, "target": [0, 0, 0]}]})",
                                 "free.json");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  problem.evaluate(problem.initial_guess(), nullptr);
  return problem.rollout().x[32];
}

KeyframeProjection project(const std::string& kind, const std::string& objectives) {
  const Scene scene =
      scene_with("{" + kFree + R"(, "controls": {"kind": ")", kind, R"("}, "objectives": )" + objectives + "}", "target.json");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  problem.evaluate(problem.initial_guess(), nullptr);
  sys->hold_step_schedule(sys->step_schedule());
  ProjectionOptions o;
  o.reach_share = 0.01;
  o.max_passes = 400;
  o.max_step = 1e3;  // the linear model holds everywhere: no cap on the step
  o.sketch = true;
  return project_onto_keyframes(problem, scene, problem.initial_guess(), o);
}

class LinearTarget : public ::testing::TestWithParam<const char*> {};

// The centre of mass 8 cm off where no force leaves it: one step meets it to a hundredth of the tolerance.
TEST_P(LinearTarget, CentreOfMassInOneOrTwoJacobians) {
  std::vector<int> all(36);
  for (int i = 0; i < 36; ++i) all[size_t(i)] = i;
  const Vec3 target = mean_of(uncontrolled_at_end(GetParam()), all) + Vec3(0.05, -0.04, 0.05);
  const KeyframeProjection p =
      project(GetParam(), R"([{"type": "center_of_mass", "frame": 16, "target": )" + vec(target) + "}]");
  EXPECT_TRUE(p.reached()) << describe(p);
  EXPECT_GT(p.start_worst, 5.0) << describe(p);
  EXPECT_LE(p.worst, 0.01) << describe(p);
  EXPECT_LE(p.iterations, 2) << describe(p);
  EXPECT_EQ(p.adjoint_passes, 3 * p.iterations);
}

// Every particle keyframed (108 residuals, sketched) at the uncontrolled end moved 6 cm as one: met to a
// hundredth of the tolerance in a few Jacobians of the sketch (what a step moves outside the sketch's rows is
// met by the next), each far fewer adjoint passes than residuals.
TEST_P(LinearTarget, WholeSheetMovedAsOneThroughTheSketch) {
  const VecX end = uncontrolled_at_end(GetParam());
  std::ostringstream objectives;
  objectives << R"([{"type": "position", "frame": 16, "particles": [)";
  for (int i = 0; i < 36; ++i) objectives << (i ? "," : "") << i;
  objectives << R"(], "targets": [)";
  for (int i = 0; i < 36; ++i) objectives << (i ? "," : "") << vec(end.segment<3>(3 * i) + Vec3(0.03, 0.04, -0.03));
  objectives << "]}]";
  const KeyframeProjection p = project(GetParam(), objectives.str());
  EXPECT_TRUE(p.reached()) << describe(p);
  EXPECT_LE(p.iterations, 4) << describe(p);
  EXPECT_LE(p.adjoint_passes, 31 * p.iterations) << describe(p);  // the sketch's rows: 1 + 10 moments x 3 axes
}

INSTANTIATE_TEST_SUITE_P(ForceKinds, LinearTarget, ::testing::Values("per_frame", "per_step", "per_frame_lattice"));

// A sheet thrown onto a sphere below it, forces per frame, per step or on the lattice: from frame 14 it lands on it.
Scene on_sphere(const std::string& kind) {
  return scene_with(R"({"time": {"fps": 30, "substeps": 2, "frames": 16}, "cloth": {"nx": 6, "ny": 6,
    "width": 0.4, "height": 0.4, "origin": [-0.2, 1.0, -0.2], "u_axis": [1, 0, 0], "v_axis": [0, 0, 1],
    "velocity": [1, 2, 0], "mass": 0.1, "air_drag": 0.1, "cg_tolerance": 1e-12, "colliders": [{"type": "sphere",
    "center": [0.45, 0.45, 0], "radius": 0.2}]}, "controls": {"kind": ")", kind, R"("}, "objectives": [
    {"type": "position", "frame": 16, "particles": [0, 17, 35], "targets": [[0.3, 0.7, 0], [0.4, 0.7, 0.1], [0.5, 0.7, 0]]},
    {"type": "center_of_mass", "frame": 8, "target": [0.3, 1.4, 0]}]})", "sphere.json");
}

class ForceResiduals : public ::testing::TestWithParam<const char*> {};

// wᵀ dr/dz from one adjoint pass against central differences of wᵀ r at two step sizes that agree, at no force
// and at random forces of a third of a particle's weight (the sheet in contact by frame 16).
TEST_P(ForceResiduals, AdjointRowsMatchCentralDifferencesInContact) {
  const Scene scene = on_sphere(GetParam());
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  ResidualFlight flight(problem, placed_keyframes(problem, scene));
  ASSERT_EQ(flight.rows(), 12);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  for (double size : {0.0, 0.3}) {
    SCOPED_TRACE(size);
    VecX z = problem.initial_guess();
    for (auto& e : z) e += size * problem.control_scale() * normal(rng);
    ASSERT_TRUE(flight.fly(z));
    sys->hold_step_schedule(sys->step_schedule());
    VecX w(flight.rows()), d(problem.size());
    for (auto& e : w) e = normal(rng);
    for (auto& e : d) e = normal(rng);
    d *= problem.control_scale() / d.norm();
    const test::ResidualDirectional c = test::residual_directional(flight, z, w, d, 1e-4, 1e-5);
    ASSERT_TRUE(c.ok);
    const double analytic = c.analytic, coarse = c.coarse, fine = c.fine;
    EXPECT_GT(std::abs(analytic), 1e-6);
    EXPECT_NEAR(coarse, fine, 1e-5 * std::abs(fine));
    EXPECT_NEAR(analytic, fine, 1e-5 * std::abs(fine)) << "coarse " << coarse;
    sys->release_step_schedule();
  }
  // Some particle is on the sphere (within a centimetre of its surface) at the keyframe: the contact is real.
  problem.evaluate(problem.initial_guess(), nullptr);
  const VecX& x = problem.rollout().x[32];
  double nearest = INFINITY;
  for (int i = 0; i < 36; ++i) nearest = std::min(nearest, (x.segment<3>(3 * i) - Vec3(0.45, 0.45, 0)).norm() - 0.2);
  EXPECT_LT(nearest, 0.01);
}

INSTANTIATE_TEST_SUITE_P(ForceKinds, ForceResiduals, ::testing::Values("per_frame", "per_step", "per_frame_lattice"));

// The sketch's rows are orthonormal, hold r, keep a small keyframe's rows as they are, and are far fewer than
// a whole-sheet keyframe's residuals.
TEST(ResidualSketch, OrthonormalHoldsTheResidualsAndKeepsSmallKeyframes) {
  PlacedKeyframe few, many;
  few.ids = {0, 5};
  few.targets = {Vec3::Zero(), Vec3::Zero()};
  for (int i = 0; i < 36; ++i) many.ids.push_back(i), many.targets.push_back(Vec3::Zero());
  const std::vector<PlacedKeyframe> placed{few, many};
  VecX x0(108);
  for (int i = 0; i < 36; ++i) x0.segment<3>(3 * i) = Vec3(0.1 * (i % 6), 1.0, 0.1 * (i / 6));
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  VecX r(residual_count(placed));
  for (auto& e : r) e = normal(rng);
  ASSERT_TRUE(sketched(placed));
  EXPECT_FALSE(sketched({few}));
  const Eigen::MatrixXd s = residual_sketch(placed, x0, r);
  EXPECT_LT(s.rows(), 30);
  EXPECT_GT(s.rows(), 6 + 9);
  EXPECT_LT((s * s.transpose() - Eigen::MatrixXd::Identity(s.rows(), s.rows())).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR((s * r).norm(), r.norm(), 1e-12 * r.norm());
  // The few particles' six residuals are each in the sketch's span.
  for (int k = 0; k < 6; ++k) {
    VecX unit = VecX::Zero(r.size());
    unit[k] = 1;
    EXPECT_NEAR((s * unit).norm(), 1.0, 1e-12);
  }
  EXPECT_EQ(residual_sketch({few}, x0, r.head(6)), Eigen::MatrixXd::Identity(6, 6));
}

// Not started on a keyframe more than near_limit tolerances off: one simulation, the start kept.
TEST(NearMissProjection, LeavesAFarKeyframeAlone) {
  const Scene scene = on_sphere("per_frame");
  auto sys = make_system(scene);
  Problem problem(scene, scene.time, *sys);
  const NearMissRule rule;
  const KeyframeProjection p =
      project_near_miss(problem, scene, problem.initial_guess(), {true, true}, 200, rule, nullptr);
  EXPECT_EQ(p.stop, ProjectionStop::kFar) << describe(p);
  EXPECT_GT(p.start_worst, rule.near_limit);
  EXPECT_EQ(p.simulations, 1);
  EXPECT_EQ(p.adjoint_passes, 0);
  EXPECT_EQ(p.z, problem.initial_guess());
  // What the strategy reads before starting one: the same worst keyframe, from the problem's own rollout.
  problem.evaluate(problem.initial_guess(), nullptr);
  EXPECT_NEAR(near_miss_worst(problem, scene), p.start_worst, 1e-9 * p.start_worst);
  const KeyframeProjection none =
      project_near_miss(problem, scene, problem.initial_guess(), {false, false}, 200, rule, nullptr);
  EXPECT_EQ(none.stop, ProjectionStop::kNotApplicable);
  // Two passes per evaluation the run left; none for a run that spent its budget (no floor by default).
  EXPECT_EQ(near_miss_passes(rule, 121, 300), 242);
  EXPECT_EQ(near_miss_passes(rule, 0, 300), 0);
  NearMissRule floored;
  floored.min_share = 0.5;
  EXPECT_EQ(near_miss_passes(floored, 10, 300), 150);
}

}  // namespace
}  // namespace kf

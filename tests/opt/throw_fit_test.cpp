// The throw fitted to a sheet's keyframes: exact on keyframes that are a ballistic rigid motion.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>

#include "opt/problem.h"
#include "opt/throw_fit.h"
#include "scene/scene.h"
#include "sim/make_system.h"

namespace kf {
namespace {

// A 5 x 5 sheet laid flat at height 1 with the scene's velocity `v`, and `keyframes` (JSON) at the end.
Scene sheet_scene(const std::string& keyframes, double drag) {
  std::ostringstream os;
  os << R"({"time": {"fps": 30, "frames": 30}, "cloth": {"nx": 5, "ny": 5, "width": 0.4, "height": 0.4,
             "origin": [-0.2, 1.0, -0.2], "u_axis": [1, 0, 0], "v_axis": [0, 0, 1], "velocity": [1, 2, 0],
             "air_drag": )"
     << drag << R"(}, "objectives": )" << keyframes << R"(, "controls": {"kind": "initial_velocity"}})";
  return parse_scene(os.str(), "fit.json");
}

void layout(const Scene& scene, VecX& x0, VecX& v0) {
  const ClothSpec& c = *scene.cloth;
  x0.resize(3 * c.nx * c.ny);
  v0.resize(x0.size());
  for (int j = 0; j < c.ny; ++j)
    for (int i = 0; i < c.nx; ++i) {
      const int k = j * c.nx + i;
      x0.segment<3>(3 * k) = c.origin + i * c.width / (c.nx - 1) * c.u_axis + j * c.height / (c.ny - 1) * c.v_axis;
      v0.segment<3>(3 * k) = c.velocity;
    }
}

// The backward Euler flight of `frames` steps (h = 1/30 s) from velocity 1 alone (s) and from gravity alone (f).
void flight(int frames, double drag, double& s, Vec3& f) {
  const double h = 1 / 30.0, a = 1 / (1 + h * drag);
  double v = 1;
  Vec3 vg = Vec3::Zero();
  s = 0;
  f = Vec3::Zero();
  for (int k = 0; k < frames; ++k) {
    v *= a;
    vg = a * (vg + h * Vec3(0, -9.81, 0));
    s += h * v;
    f += h * vg;
  }
}

// Position keyframes of all particles on `frames` of the rigid motion with mean velocity `vel` and spin `w`
// under gravity and drag `drag`, stepped as fit_throw models it.
std::string rigid_keyframes(const VecX& x0, const Vec3& vel, const Vec3& w, double drag, std::initializer_list<int> frames) {
  const int n = int(x0.size() / 3);
  Vec3 c0 = Vec3::Zero();
  for (int i = 0; i < n; ++i) c0 += x0.segment<3>(3 * i);
  c0 /= n;
  std::ostringstream os;
  os.precision(17);
  os << "[";
  bool first = true;
  for (int frame : frames) {
    double s;
    Vec3 f;
    flight(frame, drag, s, f);
    const Vec3 c = c0 + f + vel * s;
    const Mat3 r = Eigen::AngleAxisd(w.norm() * s, w.normalized()).toRotationMatrix();
    os << (first ? "" : ",") << R"({"type": "position", "frame": )" << frame << R"(, "targets": [)";
    first = false;
    for (int i = 0; i < n; ++i) {
      const Vec3 p = c + r * (x0.segment<3>(3 * i) - c0);
      os << (i ? "," : "") << "[" << p.x() << "," << p.y() << "," << p.z() << "]";
    }
    os << "]}";
  }
  os << "]";
  return os.str();
}

TEST(ThrowFit, RecoversABallisticRigidThrowFromItsKeyframes) {
  const double drag = 0.3;
  const Scene probe = sheet_scene(R"([{"type": "center_of_mass", "frame": 9, "target": [0, 1, 0]}])", drag);
  VecX x0, v0;
  layout(probe, x0, v0);
  const Vec3 vel(3.0, 2.5, -0.4), w(6.0, 0.3, -1.5);
  // Turns of 0.9 to 1.2 rad between keyframes, 3.9 rad in all: more than half a revolution.
  const Scene scene = sheet_scene(rigid_keyframes(x0, vel, w, drag, {5, 9, 14, 21}), drag);
  const auto z = fit_throw(scene, x0, v0);
  ASSERT_TRUE(z);
  EXPECT_LT((z->head<3>() - (vel - Vec3(1, 2, 0))).norm(), 1e-9) << z->transpose();
  EXPECT_LT((z->tail<3>() - w).norm(), 1e-9) << z->transpose();
}

TEST(ThrowFit, CentreOfMassKeyframesGiveTheVelocityAndNoSpin) {
  const double drag = 0.1;
  const Scene probe = sheet_scene(R"([{"type": "center_of_mass", "frame": 9, "target": [0, 1, 0]}])", drag);
  VecX x0, v0;
  layout(probe, x0, v0);
  // The centre starts at (0, 1, 0); one keyframe the rigid motion with velocity (2, 3, 1) passes through.
  double s;
  Vec3 f;
  flight(12, drag, s, f);
  const Vec3 c = Vec3(0, 1, 0) + f + Vec3(2, 3, 1) * s;
  std::ostringstream os;
  os.precision(17);
  os << R"([{"type": "center_of_mass", "frame": 12, "target": [)" << c.x() << "," << c.y() << "," << c.z() << "]}]";
  const auto z = fit_throw(sheet_scene(os.str(), drag), x0, v0);
  ASSERT_TRUE(z);
  EXPECT_LT((z->head<3>() - Vec3(1, 1, 1)).norm(), 1e-9) << z->transpose();
  EXPECT_EQ(z->tail<3>(), Vec3::Zero());
}

TEST(ThrowFit, NothingToFitWithoutAPlaceToBe) {
  const Scene scene = sheet_scene(R"([{"type": "velocity", "frame": 9, "targets": [[0, 0, 0]]}])", 0.1);
  VecX x0, v0;
  layout(scene, x0, v0);
  EXPECT_FALSE(fit_throw(scene, x0, v0));
}

// A 6 x 6 cloth thrown with a spin: keyframes where the cloth itself is at three frames (so a throw meets
// them exactly), fitted as if it were rigid, then corrected by flying it.
TEST(ThrowFit, CorrectionsBringTheFittedThrowCloserToTheClothsOwnFlight) {
  const std::string cloth = R"("time": {"fps": 30, "substeps": 2, "frames": 16}, "cloth": {"nx": 6, "ny": 6,
      "width": 0.4, "height": 0.4, "origin": [-0.2, 1.0, -0.2], "u_axis": [1, 0, 0], "v_axis": [0, 0, 1],
      "velocity": [1, 2, 0], "mass": 0.1, "air_drag": 0.1, "cg_tolerance": 1e-10})";
  const Scene thrower = parse_scene("{" + cloth + R"(, "objectives": [{"type": "center_of_mass", "frame": 8,
      "target": [0, 1, 0]}], "controls": {"kind": "initial_rigid_velocity"}})", "throw.json");
  auto sys = make_system(thrower);
  Problem fly(thrower, thrower.time, *sys);
  VecX thrown(6);
  thrown << 0.5, 1.0, -0.3, 9.0, 0.5, -2.0;  // m/s and rad/s: turned about 1.6 rad by frame 16
  fly.evaluate(thrown, nullptr);
  std::ostringstream os;
  os.precision(17);
  os << "[";
  for (int frame : {6, 11, 16}) {
    const VecX& x = fly.rollout().x[size_t(frame) * 2];
    os << (frame > 6 ? "," : "") << R"({"type": "position", "frame": )" << frame << R"(, "targets": [)";
    for (int i = 0; i < 36; ++i) os << (i ? "," : "") << "[" << x[3 * i] << "," << x[3 * i + 1] << "," << x[3 * i + 2] << "]";
    os << "]}";
  }
  os << "]";
  const Scene scene = parse_scene("{" + cloth + R"(, "objectives": )" + os.str() +
                                      R"(, "controls": {"kind": "initial_rigid_velocity", "alpha": 0}})",
                                  "keyframes.json");
  Problem problem(scene, scene.time, *sys);
  const FittedThrow none = refine_fitted_throw(problem, scene, 0), some = refine_fitted_throw(problem, scene, 3);
  ASSERT_TRUE(none.z && some.z);
  EXPECT_EQ(none.simulated, 1);
  ASSERT_EQ(some.flown.size(), 4u);
  EXPECT_EQ(some.flown.front(), none.phi);
  EXPECT_DOUBLE_EQ(problem.evaluate(*some.z, nullptr), some.phi);
  // The rigid fit alone misses the cloth's own throw; the corrections close most of the gap.
  EXPECT_GT((*none.z - thrown).norm(), 0.05 * thrown.norm()) << none.z->transpose();
  EXPECT_LT(some.phi, 0.1 * none.phi);
  EXPECT_LT((*some.z - thrown).norm(), 0.01 * thrown.norm()) << some.z->transpose();
}

}  // namespace
}  // namespace kf

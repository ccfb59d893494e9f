#include "opt/throw_fit.h"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <map>
#include <variant>

#include "opt/keyframes/keyframe_kind.h"
#include "opt/problem.h"

namespace kf {

namespace {

// What one keyframe says of the rigid motion at its time: where the sheet's centre of mass is, and
// (from three or more particles with a target each) how the sheet is turned.
struct Pose {
  Vec3 centre = Vec3::Zero();
  std::optional<Mat3> turn;
};

Vec3 centroid(const VecX& x, const std::vector<int>& ids) {
  Vec3 c = Vec3::Zero();
  for (int i : ids) c += x.segment<3>(3 * i);
  return c / double(std::max<size_t>(1, ids.size()));
}

// The rotation R minimising Σ‖R (a_i − ā) − (b_i − b̄)‖² (Kabsch); empty when the a_i are nearly collinear.
std::optional<Mat3> best_rotation(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  Vec3 ca = Vec3::Zero(), cb = Vec3::Zero();
  for (size_t i = 0; i < a.size(); ++i) ca += a[i], cb += b[i];
  ca /= double(a.size()), cb /= double(b.size());
  Mat3 h = Mat3::Zero();
  for (size_t i = 0; i < a.size(); ++i) h += (a[i] - ca) * (b[i] - cb).transpose();
  Eigen::JacobiSVD<Mat3> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 s = svd.singularValues();
  if (!(s[1] > 1e-9 * s[0])) return std::nullopt;  // a line of particles fixes no turn about itself
  Mat3 d = Mat3::Identity();
  d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return Mat3(svd.matrixV() * d * svd.matrixU().transpose());
}

// The rotation vector of R (axis times angle, the angle in [0, π]).
Vec3 rotation_vector(const Mat3& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.axis() * aa.angle();
}

// What each keyframe frame says of the sheet's pose: from the targets, or (flown given) from where the
// flown sheet has the keyframes' particles.
std::map<int, Pose> keyframe_poses(const Scene& scene, const VecX& x0, const Rollout* flown) {
  const int particles = int(x0.size() / 3);
  std::vector<int> all(particles);
  for (int i = 0; i < particles; ++i) all[i] = i;
  const Vec3 c0 = centroid(x0, all);
  // Where particle i is at a keyframe: `flown`'s state at the keyframe's frame, else the target t.
  const auto at = [&](int frame, int i, const Vec3& t) -> Vec3 {
    return flown ? Vec3(flown->x[size_t(frame) * scene.time.substeps].segment<3>(3 * i)) : t;
  };
  std::map<int, Pose> poses;  // by frame; a later keyframe on the same frame refines the first
  for (const ObjectiveSpec& o : scene.objectives) {
    const std::vector<int>& ids = o.particles.empty() ? all : o.particles;
    const Vec3 offset = c0 - centroid(x0, ids);  // from the keyframe's particles' centroid to the sheet's
    const auto centre_of = [&](const Vec3& target) {
      Vec3 c = Vec3::Zero();
      for (int i : ids) c += at(o.frame, i, target);
      return Vec3(c / double(std::max<size_t>(1, ids.size())));
    };
    const KeyframePlacement place = keyframe_placement(o);
    switch (place.kind) {
      case KeyframePlacement::Kind::kNone:
        break;
      case KeyframePlacement::Kind::kParticles: {
        if (place.targets.size() != ids.size()) {
          if (place.targets.size() == 1) poses[o.frame].centre = centre_of(place.targets[0]) + offset;
          break;
        }
        std::vector<Vec3> a, b;
        Vec3 cb = Vec3::Zero();
        for (size_t j = 0; j < ids.size(); ++j) {
          a.push_back(x0.segment<3>(3 * ids[j]));
          b.push_back(at(o.frame, ids[j], place.targets[j]));
          cb += b.back();
        }
        cb /= double(b.size());
        Pose& pose = poses[o.frame];
        pose.turn = best_rotation(a, b);
        pose.centre = cb + (pose.turn ? *pose.turn : Mat3::Identity()) * offset;
        break;
      }
      case KeyframePlacement::Kind::kCentroid:
        if (!poses.count(o.frame)) poses[o.frame].centre = centre_of(place.targets[0]) + offset;
        break;
    }
  }
  return poses;
}

}  // namespace

std::optional<VecX> fit_throw(const Scene& scene, const VecX& x0, const VecX& v0, const Rollout* flown) {
  if (!scene.cloth) return std::nullopt;
  const int particles = int(x0.size() / 3);
  std::vector<int> all(particles);
  for (int i = 0; i < particles; ++i) all[i] = i;
  const Vec3 c0 = centroid(x0, all), v_mean = centroid(v0, all);
  std::map<int, Pose> poses = keyframe_poses(scene, x0, flown);
  poses.erase(0);
  if (poses.empty()) return std::nullopt;

  // Free flight under gravity g and linear drag c as the cloth's backward Euler steps it (h: the step):
  // v_k = (v_{k-1} + h g) / (1 + h c), x_k = x_{k-1} + h v_k, so after n steps x_n = c0 + V s_n + f_n, s_n and
  // f_n the motion from V alone and from g alone. (The continuous motion is off by about g t h / 2: 2.5 cm
  // by 0.3 s at h = 1/60 s, as far as a keyframe's tolerance.)
  // The spin decays like the velocity, so the turn by step n is ω s_n about a fixed axis (the torque-free
  // wobble of the sheet left out).
  const ClothSpec& cloth = *scene.cloth;
  const double h = scene.time.h(), a = 1.0 / (1.0 + h * cloth.air_drag);
  const auto flight = [&](int frame, double& s_n, Vec3& f_n) {
    double v = 1;
    Vec3 vg = Vec3::Zero();
    s_n = 0;
    f_n = Vec3::Zero();
    for (int k = 0; k < frame * scene.time.substeps; ++k) {
      v *= a;
      vg = a * (vg + h * cloth.gravity);
      s_n += h * v;
      f_n += h * vg;
    }
  };
  Vec3 num = Vec3::Zero(), spin_num = Vec3::Zero();
  double den = 0, spin_den = 0, s_before = 0;
  Mat3 turn_before = Mat3::Identity();
  for (const auto& [frame, pose] : poses) {
    double st;
    Vec3 fall;
    flight(frame, st, fall);
    num += st * (pose.centre - c0 - fall);
    den += st * st;
    if (!pose.turn) continue;
    const double ds = st - s_before;
    spin_num += ds * rotation_vector(*pose.turn * turn_before.transpose());
    spin_den += ds * ds;
    turn_before = *pose.turn;
    s_before = st;
  }
  VecX z = VecX::Zero(6);
  z.head<3>() = num / den - v_mean;
  if (spin_den > 0) z.tail<3>() = spin_num / spin_den;
  if (!z.allFinite()) return std::nullopt;
  return z;
}

FittedThrow refine_fitted_throw(Problem& problem, const Scene& scene, int corrections) {
  FittedThrow best;
  VecX x0, v0;
  problem.system().initial_state(x0, v0);
  const std::optional<VecX> wanted = fit_throw(scene, x0, v0);
  if (!wanted) return best;
  // Broyden's method on flown_fit(z) = wanted, from the Jacobian of a rigid sheet (the identity): a cloth
  // turns more or less than a rigid body would, so a plain difference can overshoot every time.
  Eigen::Matrix<double, 6, 6> jacobian = Eigen::Matrix<double, 6, 6>::Identity();
  VecX z = *wanted, z_before, flew_before;
  for (int k = 0; k <= corrections; ++k) {
    const double phi = problem.evaluate(z, nullptr);
    ++best.simulated;
    if (problem.last_diverged()) break;
    best.flown.push_back(phi);
    if (!best.z || phi < best.phi) best.z = z, best.phi = phi;
    if (k == corrections) break;
    const std::optional<VecX> flew = fit_throw(scene, x0, v0, &problem.rollout());
    if (!flew) break;
    if (k > 0) {
      const VecX dz = z - z_before, df = *flew - flew_before;
      if (dz.squaredNorm() > 0) jacobian += (df - jacobian * dz) * dz.transpose() / dz.squaredNorm();
    }
    z_before = z;
    flew_before = *flew;
    const VecX step = jacobian.fullPivLu().solve(*wanted - *flew);
    if (!step.allFinite()) break;
    z += step;
  }
  return best;
}

}  // namespace kf

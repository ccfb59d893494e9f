// Every flock force: value, d/dx and d/dv against central finite differences.
#include <gtest/gtest.h>

#include <algorithm>

#include <functional>
#include <random>

#include "sim/flock/avoidance_force.h"
#include "sim/flock/flock_system.h"
#include "sim/flock/matching_force.h"
#include "sim/flock/smooth_kernel.h"
#include "sim/flock/wander_force.h"

namespace kf {
namespace {

constexpr double kEps = 1e-6;

// Largest |analytic - fd| relative to max(|fd|, 1e-6 x the largest fd entry).
double max_relative_error(const VecX& analytic, const VecX& fd) {
  const double floor = 1e-6 * fd.cwiseAbs().maxCoeff();
  double worst = 0;
  for (int k = 0; k < fd.size(); ++k)
    worst = std::max(worst, std::abs(analytic[k] - fd[k]) / std::max(std::abs(fd[k]), floor));
  return worst;
}

// Columns of d f / d d by central differences.
// Central differences; `step` shrinks near a kernel cut-off, where the force varies on the scale of the
// distance to it (the C2 kernel's third derivative grows like 1 / (R - |d|)).
Mat3 fd_jacobian(const std::function<Vec3(const Vec3&)>& f, const Vec3& d, double step = kEps) {
  Mat3 J;
  for (int c = 0; c < 3; ++c) {
    Vec3 e = Vec3::Zero();
    e[c] = step;
    J.col(c) = (f(d + e) - f(d - e)) / (2 * step);
  }
  return J;
}

double fd_step(const Vec3& d, double radius) {
  return std::clamp(1e-3 * std::abs(radius - d.norm()), 1e-10, kEps);
}

double mat_relative_error(const Mat3& a, const Mat3& fd) {
  Eigen::Map<const VecX> av(a.data(), 9), fv(fd.data(), 9);
  return max_relative_error(av, fv);
}

// Pair separations that matter: random, near the cut-off on both sides, tiny, coincident.
std::vector<Vec3> separations(double radius, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3> out;
  for (int k = 0; k < 40; ++k) {
    const double r = radius * std::sqrt(u(rng)), angle = 2 * M_PI * u(rng);
    out.emplace_back(r * std::cos(angle), 0, r * std::sin(angle));
  }
  out.emplace_back(radius * (1 - 1e-3), 0, 0);
  out.emplace_back(0, 0, -radius * (1 - 1e-4));
  out.emplace_back(radius * 0.6 * (1 - 1e-3), 0, radius * 0.8 * (1 - 1e-3));
  out.emplace_back(1e-9, 0, 0);
  out.emplace_back(0, 0, 0);
  return out;
}

TEST(SmoothKernel, ValueSlopeAndCutoff) {
  const double R = 1.5;
  EXPECT_EQ(smooth_kernel(0, R).w, 1.0);
  EXPECT_EQ(smooth_kernel(R * R, R).w, 0.0);
  EXPECT_EQ(smooth_kernel(R * R, R).dw_dr2, 0.0);
  EXPECT_EQ(smooth_kernel(4 * R * R, R).w, 0.0);
  for (double r2 : {0.1, 1.0, 2.0, 2.2499}) {
    const KernelWeight k = smooth_kernel(r2, R);
    ASSERT_NE(k.dw_dr2, 0.0);
    const double fd = (smooth_kernel(r2 + kEps, R).w - smooth_kernel(r2 - kEps, R).w) / (2 * kEps);
    EXPECT_NEAR(k.dw_dr2, fd, 1e-8 * std::abs(fd) + 1e-12) << "r2 " << r2;
  }
}

TEST(AvoidanceForce, RepulsiveFiniteAndZeroBeyondRadius) {
  const AvoidanceParams p{6.0, 1.5};
  EXPECT_EQ(avoidance_pair_force(p, Vec3::Zero()), Vec3::Zero());
  EXPECT_TRUE(avoidance_pair_jacobian(p, Vec3::Zero()).allFinite());
  EXPECT_GT(avoidance_pair_jacobian(p, Vec3::Zero())(0, 0), 0.0) << "coincident agents must be pushed apart";
  EXPECT_EQ(avoidance_pair_force(p, Vec3(1.5, 0, 0)), Vec3::Zero());
  EXPECT_EQ(avoidance_pair_force(p, Vec3(3, 0, 1)), Vec3::Zero());
  const Vec3 d(0.5, 0, -0.3);
  const Vec3 f = avoidance_pair_force(p, d);
  EXPECT_GT(f.dot(d), 0.0);
  EXPECT_NEAR(f.x() * d.z() - f.z() * d.x(), 0.0, 1e-15);  // parallel to d
  // Magnitude approaches k w far from contact.
  const double r = 1.2, w = std::pow(1 - r * r / 2.25, 3);
  EXPECT_NEAR(avoidance_pair_force(p, Vec3(r, 0, 0)).norm(), 6.0 * w * r / std::hypot(r, 0.45), 1e-12);
}

TEST(AvoidanceForce, JacobianMatchesFiniteDifferences) {
  const AvoidanceParams p{6.0, 1.5};
  std::mt19937_64 rng(1);
  double worst = 0;
  for (const Vec3& d : separations(p.radius, rng)) {
    const Mat3 J = avoidance_pair_jacobian(p, d);
    ASSERT_GT(J.norm(), 0.0) << d.transpose();
    ASSERT_TRUE(J.isApprox(J.transpose(), 1e-14));
    const Mat3 fd = fd_jacobian([&](const Vec3& e) { return avoidance_pair_force(p, e); }, d, fd_step(d, p.radius));
    worst = std::max(worst, mat_relative_error(J, fd));
    EXPECT_LT(mat_relative_error(J, fd), 1e-6) << "d = " << d.transpose() << "\nJ =\n" << J << "\nfd =\n" << fd;
  }
  RecordProperty("worst_relative_error", std::to_string(worst));
}

TEST(MatchingForce, PairValueAndJacobiansMatchFiniteDifferences) {
  const MatchingParams p{0.5, 3.0};
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const Vec3& d : separations(p.radius, rng)) {
    const Vec3 dv(u(rng), 0, u(rng));
    const double w = std::pow(1 - d.squaredNorm() / 9.0, 3);
    EXPECT_NEAR((matching_pair_force(p, d, dv) - 0.5 * w * dv).norm(), 0.0, 1e-15);
    const Mat3 Jx = matching_pair_dx(p, d, dv);
    const Mat3 fdx = fd_jacobian([&](const Vec3& e) { return matching_pair_force(p, e, dv); }, d, fd_step(d, p.radius));
    if (d.norm() > 1e-6) {
      ASSERT_GT(Jx.norm(), 0.0) << d.transpose();
      EXPECT_LT(mat_relative_error(Jx, fdx), 1e-6) << "d = " << d.transpose();
    } else {
      EXPECT_LT((Jx - fdx).norm(), 1e-9);  // the weight is flat at d = 0
    }
    // d f_i / d v_i = -c w I: the force depends on v_i only through dv = v_j - v_i.
    const Mat3 fdv = -fd_jacobian([&](const Vec3& e) { return matching_pair_force(p, d, e); }, dv);
    ASSERT_GT(fdv.norm(), 0.0);
    EXPECT_LT(mat_relative_error(-matching_pair_dv(p, d) * Mat3::Identity(), fdv), 1e-6);
  }
}

TEST(WanderForce, SeededSmoothAndTabulatedEqualsFormula) {
  const WanderParams p{0.5, 10, 42};
  WanderForce table(p, 3, 25);
  NeighborLists none;
  const VecX x = VecX::Zero(9), v = VecX::Zero(9);
  double biggest_jump = 0, biggest = 0;
  for (int n = 0; n < 40; ++n)
    for (int i = 0; i < 3; ++i) {
      Vec3 f = Vec3::Zero();
      table.add_force(FlockState{n, x, v, none}, i, f);
      EXPECT_EQ(f, wander_value(p, i, n));
      EXPECT_EQ(f.y(), 0.0);
      EXPECT_LE(f.cwiseAbs().maxCoeff(), 0.5);
      biggest = std::max(biggest, f.norm());
      if (n > 0) biggest_jump = std::max(biggest_jump, (f - wander_value(p, i, n - 1)).norm());
    }
  EXPECT_GT(biggest, 0.1);
  EXPECT_LT(biggest_jump, 0.5 * 2 * 1.5 * std::sqrt(2.0) / 10) << "must vary smoothly between knots";
  EXPECT_NE(wander_value(p, 0, 5), wander_value(p, 1, 5));
  EXPECT_NE(wander_value(p, 0, 5), wander_value(WanderParams{0.5, 10, 43}, 0, 5));
}

// ---- Whole-flock Jacobians, one force at a time, through the code path the adjoint uses. ----

FlockSpec only(const std::string& force, int agents) {
  FlockSpec s;
  s.agents = agents;
  s.avoidance.strength = force == "avoidance" ? 6.0 : 0;
  s.matching.strength = force == "matching" ? 0.5 : 0;
  s.centering.strength = force == "centering" ? 1.0 : 0;
  s.wander.strength = force == "wander" ? 0.5 : 0;
  s.drag.strength = force == "drag" ? 0.2 : 0;
  return s;
}

// A dense cluster, a coincident pair and, far away, pairs just inside each force's cut-off.
void configuration(int p, std::mt19937_64& rng, VecX& x, VecX& v, const FlockSpec& spec) {
  std::uniform_real_distribution<double> u(-1, 1);
  x = VecX::Zero(3 * p);
  v = VecX::Zero(3 * p);
  for (int i = 0; i < p; ++i) {
    x[3 * i] = 2.0 * u(rng);
    x[3 * i + 2] = 2.0 * u(rng);
    v[3 * i] = u(rng);
    v[3 * i + 2] = u(rng);
  }
  seg(x, 1) = seg(x, 0);
  const double radii[] = {spec.avoidance.radius, spec.matching.radius, spec.centering.radius};
  for (int k = 0; k < 3; ++k) {
    const int a = p - 2 - 2 * k;
    seg(x, a) = Vec3(100.0 + 20 * k, 0, 50);
    seg(x, a + 1) = seg(x, a) + radii[k] * (1 - 1e-3) * Vec3(0.6, 0, 0.8);
  }
}

void check_force_jacobians(const std::string& force, bool expect_K, bool expect_D) {
  const int p = 24;
  const FlockSpec spec = only(force, p);
  FlockSystem sys(spec, 1.0 / 30, 10, 3);
  std::mt19937_64 rng(7);
  VecX x, v;
  configuration(p, rng, x, v, spec);
  VecX y(3 * p);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < 3 * p; ++k) y[k] = k % 3 == 1 ? 0.0 : u(rng);

  VecX f, KTy, DTy;
  sys.forces(2, x, v, f);
  ASSERT_TRUE(f.allFinite());
  ASSERT_GT(f.norm(), 0.0) << force;
  for (int i = 0; i < p; ++i) ASSERT_EQ(f[3 * i + 1], 0.0);
  sys.apply_KT_DT(2, x, v, y, KTy, DTy);

  // Columns of K and D by central differences of the whole force vector, then y^T times them: agents
  // a perturbation does not reach give exactly zero, so round-off stays local to each neighbourhood.
  auto f_at = [&](const VecX& xx, const VecX& vv) {
    VecX ff;
    sys.forces(2, xx, vv, ff);
    return ff;
  };
  VecX fdK = VecX::Zero(3 * p), fdD = VecX::Zero(3 * p);
  for (int k = 0; k < 3 * p; ++k) {
    if (k % 3 == 1) continue;
    VecX xp = x, xm = x, vp = v, vm = v;
    xp[k] += kEps;
    xm[k] -= kEps;
    vp[k] += kEps;
    vm[k] -= kEps;
    fdK[k] = y.dot(f_at(xp, v) - f_at(xm, v)) / (2 * kEps);
    fdD[k] = y.dot(f_at(x, vp) - f_at(x, vm)) / (2 * kEps);
  }
  if (expect_K) {
    ASSERT_GT(fdK.norm(), 1e-3) << force;
    EXPECT_LT(max_relative_error(KTy, fdK), 1e-5) << force << "\nK^T y: " << KTy.transpose() << "\nfd:    " << fdK.transpose();
  } else {
    EXPECT_EQ(KTy.norm(), 0.0);
    EXPECT_EQ(fdK.norm(), 0.0);
  }
  if (expect_D) {
    ASSERT_GT(fdD.norm(), 1e-3) << force;
    EXPECT_LT(max_relative_error(DTy, fdD), 1e-5) << force << "\nD^T y: " << DTy.transpose() << "\nfd:    " << fdD.transpose();
  } else {
    EXPECT_EQ(DTy.norm(), 0.0);
    EXPECT_EQ(fdD.norm(), 0.0);
  }
  // Near-cut-off pairs (far from the cluster) must contribute for the neighbour forces.
  if (force == "avoidance") {
    EXPECT_GT(seg(f, p - 2).norm(), 0.0);
  }
  if (force == "matching") {
    EXPECT_GT(seg(f, p - 4).norm(), 0.0);
  }
  if (force == "centering") {
    EXPECT_GT(seg(f, p - 6).norm(), 0.0);
  }
}

TEST(FlockJacobians, Avoidance) { check_force_jacobians("avoidance", true, false); }
TEST(FlockJacobians, Matching) { check_force_jacobians("matching", true, true); }
TEST(FlockJacobians, CenteringIsNotSymmetricAndUsesTheTranspose) {
  check_force_jacobians("centering", true, false);
  // K y != K^T y: apply K by finite differences along y and compare with K^T y.
  const FlockSpec spec = only("centering", 12);
  FlockSystem sys(spec, 1.0 / 30, 10, 3);
  std::mt19937_64 rng(9);
  VecX x, v;
  configuration(12, rng, x, v, spec);
  VecX y = VecX::Zero(36);
  seg(y, 0) = Vec3(1, 0, 0.5);
  VecX fp, fm, KTy, DTy;
  sys.forces(0, x + kEps * y, v, fp);
  sys.forces(0, x - kEps * y, v, fm);
  const VecX Ky = (fp - fm) / (2 * kEps);
  sys.apply_KT_DT(0, x, v, y, KTy, DTy);
  EXPECT_GT((Ky - KTy).norm(), 1e-3 * Ky.norm());
}
TEST(FlockJacobians, Drag) { check_force_jacobians("drag", false, true); }
TEST(FlockJacobians, Wander) { check_force_jacobians("wander", false, false); }

}  // namespace
}  // namespace kf

// Cloth force terms: values and Jacobians against central finite differences.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

#include "scene/cloth_spec.h"
#include "sim/cape/body_collider.h"
#include "sim/cape/self_collider.h"
#include "sim/character/character.h"
#include "sim/cloth/air_drag_term.h"
#include "sim/cloth/buckling_spring.h"
#include "sim/cloth/cloth_terms.h"
#include "sim/cloth/spring_damping.h"
#include "character_test_util.h"
#include "cloth_term_check.h"

namespace kf {
namespace {

// Largest per-component error of `a` against `fd`, relative to max(|fd_ij|, 1e-6 max|fd|).
double relative_error(const Mat3& a, const Mat3& fd) {
  const double floor = 1e-6 * fd.cwiseAbs().maxCoeff();
  return ((a - fd).cwiseAbs().array() / fd.cwiseAbs().array().max(floor)).maxCoeff();
}

// d(force on a)/d(x_b) by central differences of `force(x)`.
template <class F>
Mat3 fd_jacobian(F force, VecX x, int particle, double eps) {
  Mat3 J;
  for (int k = 0; k < 3; ++k) {
    const double x0 = x[3 * particle + k];
    x[3 * particle + k] = x0 + eps;
    const Vec3 fp = force(x);
    x[3 * particle + k] = x0 - eps;
    const Vec3 fm = force(x);
    x[3 * particle + k] = x0;
    J.col(k) = (fp - fm) / (2 * eps);
  }
  return J;
}

BucklingSpring test_spring() {
  BucklingSpring s;
  s.a = 0;
  s.b = 1;
  s.rest = 0.1;
  s.k = 400;
  s.k_post = 40;
  s.f_buckle = 400 * 0.1 * 0.005;
  return s;
}

// Two particles: a at a random point, b at `ratio` * rest along a random direction.
VecX pair_at(double ratio, double rest, std::mt19937& rng) {
  std::normal_distribution<double> N;
  VecX x(6);
  const Vec3 a(N(rng), N(rng), N(rng));
  const Vec3 dir = Vec3(N(rng), N(rng), N(rng)).normalized();
  seg(x, 0) = a;
  seg(x, 1) = a + ratio * rest * dir;
  return x;
}

TEST(ClothSpring, TensionIsC1AndMatchesItsSlopeAndCurvature) {
  const BucklingSpring s = test_spring();
  double T, dT, d2T, Tp, dTp, d2Tp, Tm, dTm, d2Tm;
  spring_tension(s, s.rest * 1.1, T, dT, d2T);
  EXPECT_NEAR(T, s.k * 0.1 * s.rest, 1e-12);
  EXPECT_EQ(d2T, 0.0);
  // Slope continuous at the rest length (no kink for the optimiser).
  spring_tension(s, s.rest * (1 + 1e-12), Tp, dTp, d2Tp);
  spring_tension(s, s.rest * (1 - 1e-12), Tm, dTm, d2Tm);
  EXPECT_NEAR(dTp, dTm, 1e-6 * s.k);
  // Deep compression: force near the buckling load, stiffness near the post-buckling stiffness.
  spring_tension(s, s.rest * 0.5, T, dT, d2T);
  EXPECT_LT(T, -s.f_buckle);
  EXPECT_NEAR(dT, s.k_post, 1e-6 * s.k);
  for (double ratio : {1.3, 1.0001, 0.9999, 0.998, 0.95, 0.6, 0.05}) {
    const double L = s.rest * ratio, eps = 1e-8;
    spring_tension(s, L, T, dT, d2T);
    spring_tension(s, L + eps, Tp, dTp, d2Tp);
    spring_tension(s, L - eps, Tm, dTm, d2Tm);
    ASSERT_GT(std::abs(dT), 0);
    EXPECT_NEAR(dT, (Tp - Tm) / (2 * eps), 1e-6 * s.k) << "ratio " << ratio;
    EXPECT_NEAR(d2T, (dTp - dTm) / (2 * eps), 1e-6 * std::max(std::abs(d2T), s.k / s.rest)) << "ratio " << ratio;
    EXPECT_GE(dT, 0);
  }
}

TEST(ClothSpring, EnergyIsZeroAtRestAndItsGradientIsMinusTheForce) {
  const BucklingSpring s = test_spring();
  std::mt19937 rng(3);
  EXPECT_LT(spring_energy(s, pair_at(1.0, s.rest, rng)), 1e-20);  // at rest up to rounding
  for (double ratio : {1.25, 1.01, 0.999, 0.99, 0.9, 0.5, 0.1}) {
    const VecX x = pair_at(ratio, s.rest, rng);
    EXPECT_GT(spring_energy(s, x), 0) << "ratio " << ratio;
    // d(energy)/d(x_a) = -(force on a), by central differences.
    const double eps = 1e-7 * s.rest;
    Vec3 grad;
    for (int k = 0; k < 3; ++k) {
      VecX xp = x, xm = x;
      xp[k] += eps;
      xm[k] -= eps;
      grad[k] = (spring_energy(s, xp) - spring_energy(s, xm)) / (2 * eps);
    }
    const Vec3 f = spring_force(s, x);
    ASSERT_GT(f.norm(), 0);
    EXPECT_LT((grad + f).norm(), 1e-6 * f.norm()) << "ratio " << ratio << ": " << grad.transpose() << " vs "
                                                  << -f.transpose();
  }
  // Zero rest length: k |d|^2 / 2.
  BucklingSpring z = s;
  z.rest = 0;
  const VecX x = pair_at(1.0, 0.3, rng);
  EXPECT_NEAR(spring_energy(z, x), 0.5 * z.k * 0.09, 1e-12);
}

// The closed-form energy against the tension integrated numerically (composite Simpson, 4,000 intervals):
// E(e) = -integral of T over compressions 0 .. e, inside the blend, at its end and beyond.
TEST(ClothSpring, EnergyIsTheIntegralOfTheTensionAcrossTheBlendAndBeyond) {
  const BucklingSpring s = test_spring();
  const double e0 = kBuckleBlend * s.f_buckle / (s.k - s.k_post);
  std::mt19937 rng(11);
  for (double e : {0.05 * e0, 0.5 * e0, e0, 1.7 * e0, 6.0 * e0}) {
    const int n = 4000;
    auto tension = [&](double c) {
      double T, dT, d2T;
      spring_tension(s, s.rest - c, T, dT, d2T);
      return T;
    };
    double sum = tension(0) + tension(e);
    for (int i = 1; i < n; ++i) sum += (i % 2 ? 4 : 2) * tension(e * i / n);
    const double integral = -sum * e / (3 * n);
    const double energy = spring_energy(s, pair_at((s.rest - e) / s.rest, s.rest, rng));
    EXPECT_NEAR(energy, integral, 1e-9 * integral) << "e / e0 = " << e / e0;
  }
}

TEST(ClothSpring, JacobianMatchesFiniteDifferencesInTensionAndCompression) {
  const BucklingSpring s = test_spring();
  std::mt19937 rng(7);
  for (double ratio : {1.25, 1.01, 0.999, 0.99, 0.9, 0.5, 0.1, 1e-3}) {
    for (int trial = 0; trial < 4; ++trial) {
      const VecX x = pair_at(ratio, s.rest, rng);
      const double eps = 1e-6 * ratio * s.rest;
      auto force = [&](const VecX& y) { return spring_force(s, y); };
      const Mat3 B = spring_jacobian(s, x, /*definite=*/false);
      const Mat3 fd_b = fd_jacobian(force, x, 1, eps);
      const Mat3 fd_a = fd_jacobian(force, x, 0, eps);
      ASSERT_GT(fd_b.norm(), 0) << "ratio " << ratio;
      EXPECT_LT(relative_error(B, fd_b), 1e-5) << "ratio " << ratio << "\nB=\n" << B << "\nfd=\n" << fd_b;
      EXPECT_LT(relative_error(-B, fd_a), 1e-5) << "ratio " << ratio;
      EXPECT_LT((B - B.transpose()).norm(), 1e-12 * B.norm());
    }
  }
}

TEST(ClothSpring, JacobianMatchesFiniteDifferencesAtTinyLengths) {
  // Squeezed to 1e-4 … 1e-8 of its rest length, just above the 1e-9 cut-off: the transverse stiffness
  // T/s is huge and negative, and the Jacobian must still be its exact derivative. Particle a sits at
  // the origin so the difference x_b - x_a carries no round-off from large coordinates.
  const BucklingSpring s = test_spring();
  std::mt19937 rng(13);
  std::normal_distribution<double> N;
  for (double ratio : {1e-4, 1e-6, 1e-8}) {
    VecX x = VecX::Zero(6);
    seg(x, 1) = ratio * s.rest * Vec3(N(rng), N(rng), N(rng)).normalized();
    const double eps = 1e-4 * ratio * s.rest;
    auto force = [&](const VecX& y) { return spring_force(s, y); };
    const Mat3 B = spring_jacobian(s, x, /*definite=*/false);
    const Mat3 fd = fd_jacobian(force, x, 1, eps);
    ASSERT_TRUE(B.allFinite());
    ASSERT_GT(fd.norm(), 0);
    EXPECT_LT(relative_error(B, fd), 1e-6) << "ratio " << ratio << "\nB=\n" << B << "\nfd=\n" << fd;
    EXPECT_LT(relative_error(-B, fd_jacobian(force, x, 0, eps)), 1e-6) << "ratio " << ratio;
  }
}

TEST(ClothSpring, ZeroRestLengthSpringIsLinearAndIsotropicAtEveryLength) {
  // L = 0: f_a = k d and B = k I, down to coincident particles (where d/|d| does not exist).
  BucklingSpring s = test_spring();
  s.rest = 0;
  s.f_buckle = 0;
  std::mt19937 rng(17);
  std::normal_distribution<double> N;
  for (double len : {0.3, 1e-6, 1e-12, 1e-170, 0.0}) {
    VecX x(6);
    seg(x, 0) = Vec3(N(rng), N(rng), N(rng));
    seg(x, 1) = seg(x, 0) + len * Vec3(N(rng), N(rng), N(rng)).normalized();
    const Vec3 f = spring_force(s, x);
    ASSERT_TRUE(f.allFinite()) << len;
    EXPECT_LT((f - s.k * (seg(x, 1) - seg(x, 0))).norm(), 1e-12 * s.k) << len;
    for (bool definite : {false, true}) {
      const Mat3 B = spring_jacobian(s, x, definite);
      ASSERT_TRUE(B.allFinite()) << len;
      EXPECT_LT((B - s.k * Mat3::Identity()).norm(), 1e-12 * s.k) << len;
    }
    // Finite differences straddle the coincident point too: the force is linear there.
    const Mat3 fd = fd_jacobian([&](const VecX& y) { return spring_force(s, y); }, x, 1, 1e-6);
    EXPECT_LT(relative_error(spring_jacobian(s, x, false), fd), 1e-8) << len;
    // Damping along an undefined direction is 0, never NaN.
    const VecX v = VecX::Ones(6);
    EXPECT_TRUE(damping_force(s, 0.1, x, v).allFinite()) << len;
    EXPECT_TRUE(damping_jacobian_v(s, 0.1, x).allFinite()) << len;
    EXPECT_TRUE(damping_jacobian_x(s, 0.1, x, v).allFinite()) << len;
  }
}

TEST(ClothSpring, DefiniteJacobianIsPositiveSemidefinite) {
  const BucklingSpring s = test_spring();
  std::mt19937 rng(3);
  for (double ratio : {1.2, 0.9, 0.3}) {
    const VecX x = pair_at(ratio, s.rest, rng);
    Eigen::SelfAdjointEigenSolver<Mat3> eig(spring_jacobian(s, x, true));
    EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-12) << "ratio " << ratio;
    Eigen::SelfAdjointEigenSolver<Mat3> exact(spring_jacobian(s, x, false));
    if (ratio < 1) {
      EXPECT_LT(exact.eigenvalues().minCoeff(), 0);  // what the definite form removes
    }
  }
}

// The definite transverse stiffness fades in over the spring's own ramp (the scene's transverse_ramp): half
// of T/s halfway up it (the smoothstep's midpoint), all of it beyond; and the position
// derivative the exact adjoint uses matches central differences of p . B q inside the ramp, at two steps.
TEST(ClothSpring, DefiniteTransverseStiffnessFadesInOverTheSpringsRamp) {
  EXPECT_EQ(ClothSpec().transverse_ramp, kTransverseRamp);
  std::mt19937 rng(29);
  std::normal_distribution<double> N;
  for (double ramp : {kTransverseRamp, 0.004}) {
    BucklingSpring s = test_spring();
    s.transverse_ramp = ramp;
    for (double strain : {0.5 * ramp, 2 * ramp}) {
      const VecX x = pair_at(1 + strain, s.rest, rng);
      const Vec3 n = (seg(x, 1) - seg(x, 0)).normalized();
      const Vec3 t = n.cross(Vec3(N(rng), N(rng), N(rng))).normalized();  // transverse
      const double T = s.k * strain * s.rest, length = (1 + strain) * s.rest;
      const double fade = strain < ramp ? 0.5 : 1.0;
      EXPECT_NEAR(t.dot(spring_jacobian(s, x, true) * t), fade * T / length, 1e-9 * T / length) << ramp << " " << strain;
      EXPECT_NEAR(t.dot(spring_jacobian(s, x, false) * t), T / length, 1e-9 * T / length);
    }
    const VecX x = pair_at(1 + 0.3 * ramp, s.rest, rng);
    const Vec3 p(N(rng), N(rng), N(rng)), q(N(rng), N(rng), N(rng));
    const Vec3 d = spring_jacobian_derivative(s, x, true, p, q);
    ASSERT_GT(d.norm(), 0);
    for (double step : {1e-3, 1e-4}) {
      const double eps = step * ramp * s.rest;  // well inside the ramp
      Vec3 fd;
      for (int k = 0; k < 3; ++k) {
        VecX xp = x, xm = x;
        xp[3 + k] += eps;
        xm[3 + k] -= eps;
        fd[k] = (p.dot(spring_jacobian(s, xp, true) * q) - p.dot(spring_jacobian(s, xm, true) * q)) / (2 * eps);
      }
      EXPECT_LT((d - fd).norm(), 1e-6 * d.norm()) << "ramp " << ramp << ", step " << step;
    }
  }
}

TEST(ClothSpring, ZeroLengthAndNearlyDegenerateSpringsStayFinite) {
  const BucklingSpring s = test_spring();
  VecX x = VecX::Zero(6);
  x << 0.3, 0.2, 0.1, 0.3, 0.2, 0.1;  // zero length
  VecX v = VecX::Ones(6);
  EXPECT_TRUE(spring_force(s, x).allFinite());
  EXPECT_TRUE(spring_jacobian(s, x, false).allFinite());
  EXPECT_TRUE(spring_jacobian(s, x, true).allFinite());
  EXPECT_TRUE(damping_force(s, 0.1, x, v).allFinite());
  EXPECT_TRUE(damping_jacobian_x(s, 0.1, x, v).allFinite());
  EXPECT_TRUE(damping_jacobian_v(s, 0.1, x).allFinite());
  for (double len : {1e-300, 1e-20, 1e-11, 1e-9}) {
    x[3] = 0.3 + len;
    EXPECT_TRUE(spring_force(s, x).allFinite()) << len;
    EXPECT_TRUE(spring_jacobian(s, x, false).allFinite()) << len;
    EXPECT_TRUE(damping_jacobian_x(s, 0.1, x, v).allFinite()) << len;
  }
}

TEST(ClothDamping, JacobiansMatchFiniteDifferences) {
  const BucklingSpring s = test_spring();
  const double c = 0.3;
  std::mt19937 rng(11);
  std::normal_distribution<double> N;
  for (double ratio : {1.2, 0.8, 0.05}) {
    for (int trial = 0; trial < 4; ++trial) {
      const VecX x = pair_at(ratio, s.rest, rng);
      VecX v(6);
      for (int k = 0; k < 6; ++k) v[k] = N(rng);
      const double eps = 1e-4 * ratio * s.rest;
      const Mat3 Jx = damping_jacobian_x(s, c, x, v);
      const Mat3 fdx = fd_jacobian([&](const VecX& y) { return damping_force(s, c, y, v); }, x, 1, eps);
      ASSERT_GT(fdx.norm(), 0);
      EXPECT_LT(relative_error(Jx, fdx), 1e-5) << "ratio " << ratio;
      const Mat3 Jv = damping_jacobian_v(s, c, x);
      const Mat3 fdv = fd_jacobian([&](const VecX& w) { return damping_force(s, c, x, w); }, v, 1, 1e-4);
      const Mat3 fdv_a = fd_jacobian([&](const VecX& w) { return damping_force(s, c, x, w); }, v, 0, 1e-4);
      ASSERT_GT(fdv.norm(), 0);
      EXPECT_LT(relative_error(Jv, fdv), 1e-7);
      EXPECT_LT(relative_error(-Jv, fdv_a), 1e-7);
    }
  }
}

// The exact adjoint's matrix-free products against the Jacobians they stand for, in tension, inside the
// buckling blend, deep in compression, near zero length and at zero rest length.
TEST(ClothSpring, AdjointProductsMatchTheJacobians) {
  std::mt19937 rng(23);
  std::normal_distribution<double> N;
  auto close = [](const Vec3& a, const Vec3& b) { return (a - b).norm() <= 1e-13 * std::max(1.0, b.norm()); };
  for (double rest : {0.1, 0.0})
    for (double ratio : {1.2, 1.001, 0.999, 0.8, 0.05, 1e-10}) {
      BucklingSpring s = test_spring();
      s.rest = rest;
      const VecX x = pair_at(ratio, rest > 0 ? rest : 0.1, rng);
      VecX v(6);
      for (int k = 0; k < 6; ++k) v[k] = N(rng);
      const Vec3 p(N(rng), N(rng), N(rng)), q(N(rng), N(rng), N(rng));
      Vec3 f;
      Mat3 K;
      SpringState state;
      spring_force_and_definite_jacobian(s, x, f, K, state);
      EXPECT_EQ(f, spring_force(s, x));
      EXPECT_EQ(K, spring_jacobian(s, x, true));
      for (bool derivative : {false, true}) {
        Vec3 Bp, dpq;
        spring_adjoint_products(s, state, derivative, p, q, Bp, dpq);
        EXPECT_TRUE(close(Bp, spring_jacobian(s, x, false) * p)) << rest << " " << ratio;
        EXPECT_TRUE(close(dpq, derivative ? spring_jacobian_derivative(s, x, true, p, q) : Vec3::Zero()))
            << rest << " " << ratio;
        const Vec3 damping = damping_jacobian_x(s, 0.3, x, v).transpose() * p +
                             (derivative ? damping_jacobian_v_derivative(s, 0.3, x, p, q) : Vec3::Zero());
        EXPECT_TRUE(close(damping_adjoint_products(s, 0.3, state, v, p, derivative, q), damping)) << rest << " " << ratio;
      }
    }
}

TEST(ClothDamping, RigidMotionIsNotDamped) {
  const BucklingSpring s = test_spring();
  std::mt19937 rng(5);
  const VecX x = pair_at(1.1, s.rest, rng);
  VecX v(6);
  v << 1, 2, 3, 1, 2, 3;  // translation
  EXPECT_LT(damping_force(s, 0.5, x, v).norm(), 1e-14);
  const Vec3 w(0.3, -0.2, 0.7), d = seg(x, 1) - seg(x, 0);  // rotation about a
  seg(v, 0).setZero();
  seg(v, 1) = w.cross(d);
  EXPECT_LT(damping_force(s, 0.5, x, v).norm(), 1e-14);
}

TEST(ClothAirDrag, JacobianMatchesFiniteDifferences) {
  const double c = 0.7, m = 0.02;
  const Vec3 v(0.3, -1.0, 2.0);
  Mat3 fd;
  for (int k = 0; k < 3; ++k) {
    Vec3 vp = v, vm = v;
    vp[k] += 1e-5;
    vm[k] -= 1e-5;
    fd.col(k) = (air_drag_force(c, m, vp) - air_drag_force(c, m, vm)) / 2e-5;
  }
  ASSERT_GT(fd.norm(), 0);
  EXPECT_LT(relative_error(air_drag_jacobian_v(c, m), fd), 1e-8);
}

}  // namespace
}  // namespace kf

// Every term of the cloth's list through the one check of tests/sim/cloth_term_check.h: energy gradient,
// definite blocks, and the exact adjoint's shares against central differences at two step sizes, on
// compressed, stretched and contact states of a small sheet.
namespace kf {
namespace {

const char* kSheet = R"({"nx": 4, "ny": 4, "width": 0.3, "height": 0.3, "mass": 0.1, "damping": 0.3,
                         "air_drag": 0.5, "origin": [-0.15, 0.02, -0.15], "v_axis": [0, 0, 1]})";

TEST(ClothForces, GravityTermIsMinusItsEnergyGradientAndHasNoAdjointShare) {
  const auto sheet = test::term_sheet(kSheet);
  VecX x, v;
  test::perturbed_state(*sheet, 0.9, 0.005, 0.3, 1, x, v);
  const test::TermCheck c = test::check_term(test::TermProbe<GravityTerm>(*sheet), x, v, 2);
  EXPECT_GT(c.force, 0);
  EXPECT_GT(c.energy_gradient, 0);
}

TEST(ClothForces, AirDragTermsDampingBlockIsItsExactVelocityJacobian) {
  const auto sheet = test::term_sheet(kSheet);
  VecX x, v;
  test::perturbed_state(*sheet, 0.9, 0.005, 0.3, 3, x, v);
  const test::TermCheck c = test::check_term(test::TermProbe<AirDragTerm>(*sheet), x, v, 4);
  EXPECT_GT(c.force, 0);
}

TEST(ClothForces, SpringTermMatchesFiniteDifferencesCompressedAndStretched) {
  const auto sheet = test::term_sheet(kSheet);
  for (double squeeze : {0.8, 0.97, 1.06}) {
    SCOPED_TRACE(squeeze);
    VecX x, v;
    test::perturbed_state(*sheet, squeeze, 0.004, 0.3, 5, x, v);
    // Steps of 2e-7 m: on the wavy sheet (the default waviness) stretched 6 %, central differences at 1e-5,
    // 3e-6 and 1e-6 m miss the adjoint x share by 2.1e-3, 1.9e-4 and 2.1e-5 (its largest entry 17.6), falling
    // with the step squared as truncation does, and agree with it from 3e-7 m down.
    const test::TermCheck c = test::check_term(test::TermProbe<SpringTerm>(*sheet), x, v, 6, 2e-7);
    EXPECT_GT(c.energy_gradient, 0);
    EXPECT_GT(c.adjoint_x, 0);
  }
}

TEST(ClothForces, SpringDampingTermMatchesFiniteDifferencesCompressedAndStretched) {
  const auto sheet = test::term_sheet(kSheet);
  for (double squeeze : {0.8, 1.06}) {
    SCOPED_TRACE(squeeze);
    VecX x, v;
    test::perturbed_state(*sheet, squeeze, 0.004, 0.5, 7, x, v);
    const test::TermCheck c = test::check_term(test::TermProbe<SpringDampingTerm>(*sheet), x, v, 8);
    EXPECT_GT(c.force, 0);
    EXPECT_GT(c.adjoint_x, 0);
  }
}

// The sheet lies within the contact thickness of each collider (ground, sphere, torus, capsule).
TEST(ClothForces, ContactTermMatchesFiniteDifferencesInContact) {
  const char* colliders[] = {
      R"({"type": "ground", "center": [0, 0, 0], "axis": [0, 1, 0], "thickness": 0.03, "stiffness": 3000})",
      R"({"type": "sphere", "center": [0, -0.2, 0], "radius": 0.21, "thickness": 0.03, "stiffness": 3000})",
      R"({"type": "torus", "center": [0, -0.02, 0], "axis": [0, 1, 0], "radius": 0.12, "tube_radius": 0.03,
          "thickness": 0.03, "stiffness": 3000})",
      R"({"type": "capsule", "a": [-0.2, -0.005, 0], "b": [0.2, -0.005, 0], "radius": 0.03, "thickness": 0.03,
          "stiffness": 3000})",
  };
  for (const char* col : colliders) {
    SCOPED_TRACE(col);
    std::string cloth = kSheet;
    cloth.insert(cloth.rfind('}'), std::string(R"(, "colliders": [)") + col + "]");
    const auto sheet = test::term_sheet(cloth);
    VecX x, v;
    test::perturbed_state(*sheet, 0.95, 0.004, 0.3, 9, x, v);
    const test::TermCheck c = test::check_term(test::TermProbe<ContactTerm>(*sheet), x, v, 10);
    EXPECT_GT(c.force, 0) << "no contact: the check would not cover it";
    EXPECT_GT(c.energy_gradient, 0);
    EXPECT_GT(c.adjoint_x, 0);
  }
}

// Friction (FrictionTerm) at each collider, in the sticking regime (slip about 1e-4 m/s, far below the
// friction_velocity of 0.01) and sliding (about 0.3 m/s): the force, its damping block (the exact df/dv) and
// the adjoint's x and v shares, which hold the derivatives of the damping block.
constexpr double kStickingSpeed = 1e-4, kSlidingSpeed = 0.3;

TEST(ClothForces, FrictionTermMatchesFiniteDifferencesOnEveryColliderStickingAndSliding) {
  const char* colliders[] = {
      R"({"type": "ground", "center": [0, 0, 0], "axis": [0, 1, 0], "thickness": 0.03, "stiffness": 3000,
          "friction": 0.5})",
      R"({"type": "sphere", "center": [0, -0.2, 0], "radius": 0.21, "thickness": 0.03, "stiffness": 3000,
          "friction": 0.4})",
      R"({"type": "torus", "center": [0, -0.02, 0], "axis": [0, 1, 0], "radius": 0.12, "tube_radius": 0.03,
          "thickness": 0.03, "stiffness": 3000, "friction": 0.8})",
      R"({"type": "capsule", "a": [-0.2, -0.005, 0], "b": [0.2, -0.005, 0], "radius": 0.03, "thickness": 0.03,
          "stiffness": 3000, "friction": 0.4, "friction_velocity": 0.02})",
  };
  for (const char* col : colliders)
    for (double speed : {kStickingSpeed, kSlidingSpeed}) {
      SCOPED_TRACE(std::string(col) + " speed " + std::to_string(speed));
      std::string cloth = kSheet;
      cloth.insert(cloth.rfind('}'), std::string(R"(, "colliders": [)") + col + "]");
      const auto sheet = test::term_sheet(cloth);
      ASSERT_GT(sheet->colliders[0]->friction_params().mu, 0);
      VecX x, v;
      test::perturbed_state(*sheet, 0.95, 0.004, speed, 11, x, v);
      const test::TermCheck c = test::check_term(test::TermProbe<FrictionTerm>(*sheet), x, v, 12);
      EXPECT_GT(c.force, 0) << "no friction: the check would not cover it";
      EXPECT_GT(c.adjoint_x, 0);
      EXPECT_GT(c.adjoint_v, 0);
    }
}

TEST(ClothForces, FrictionTermIsNothingWithoutCoefficientOrContact) {
  std::string cloth = kSheet;
  cloth.insert(cloth.rfind('}'),
               R"(, "colliders": [{"type": "ground", "center": [0, 0, 0], "thickness": 0.05, "friction": 0}, {"type": "sphere", "center": [0, -5, 0], "friction": 0.5}])");
  const auto sheet = test::term_sheet(cloth);
  VecX x, v;
  test::perturbed_state(*sheet, 0.95, 0.004, kSlidingSpeed, 13, x, v);
  VecX f;
  MatX K, D;
  test::TermProbe<ContactTerm>(*sheet).eval(x, v, f, K, D);
  ASSERT_GT(f.cwiseAbs().maxCoeff(), 0.0) << "the sheet must touch the frictionless ground";
  test::TermProbe<FrictionTerm>(*sheet).eval(x, v, f, K, D);
  EXPECT_EQ(f.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(D.cwiseAbs().maxCoeff(), 0.0);
}

// Self contact: a sheet squeezed along its width until neighbours along it are within the pair thickness;
// friction acts on each pair's relative slip, with the cross couplings in add_adjoint_coupled.
TEST(ClothForces, FrictionTermMatchesFiniteDifferencesInSelfContact) {
  for (double speed : {kStickingSpeed, kSlidingSpeed}) {
    SCOPED_TRACE(speed);
    auto sheet = test::term_sheet(kSheet);
    auto self = std::make_unique<SelfCollider>(sheet->particles(), 0.045, 500.0, 0.5 * 0.045);
    self->set_friction({0.3, 0.01});
    SelfCollider* pairs = self.get();
    sheet->colliders.push_back(std::move(self));
    sheet->prepare = [pairs](const VecX& x, const VecX& v) { pairs->update(x, v); };
    VecX x, v;
    test::perturbed_state(*sheet, 0.3, 0.004, speed, 15, x, v);
    const test::TermCheck c = test::check_term(test::TermProbe<FrictionTerm>(*sheet), x, v, 16);
    EXPECT_GT(c.force, 0) << "no pair in contact";
    EXPECT_GT(c.adjoint_x, 0);
    EXPECT_GT(c.adjoint_v, 0);
  }
}

}  // namespace
}  // namespace kf

// The character's body (BodyCollider suite: Embree runs without floating-point traps): particles just
// outside faces of the posed, moving body, sticking and sliding relative to its surface.
namespace kf {
namespace {

TEST(BodyCollider, FrictionTermMatchesFiniteDifferences) {
  Character ch(test::character_asset());
  VecX pose, next;
  ch.pose(1.5, pose);
  ch.pose(1.5 + 1.0 / 30, next);
  const double thickness = 0.01;
  for (double speed : {kStickingSpeed, kSlidingSpeed}) {
    SCOPED_TRACE(speed);
    auto sheet = test::term_sheet(kSheet);
    auto body = std::make_unique<BodyCollider>(ch.triangles(), ch.vertex_count(), thickness, 2000.0, 0.05, 0.5 * thickness);
    body->set_pose(pose);
    const VecX vel = (next - pose) * 30.0;
    body->set_velocity(vel);
    body->set_friction({0.5, 0.01});
    const BodyCollider& b = *body;
    sheet->colliders.push_back(std::move(body));
    // Each particle near the middle of a face, within the thickness, where the closest point stays on that
    // face under the differences' steps; moving with the surface plus a seeded slip of about `speed`.
    std::mt19937 rng(21);
    std::uniform_int_distribution<int> pick(0, ch.triangle_count() - 1);
    std::uniform_real_distribution<double> U(0, 1);
    std::normal_distribution<double> N;
    const int p = sheet->particles();
    VecX x(3 * p), v(3 * p);
    int placed = 0;
    for (int trial = 0; trial < 2000 && placed < p; ++trial) {
      const int f = pick(rng);
      const Vec3 A = seg(pose, ch.triangles()(f, 0)), B = seg(pose, ch.triangles()(f, 1)), C = seg(pose, ch.triangles()(f, 2));
      const Vec3 at = (A + B + C) / 3 + (0.002 + 0.005 * U(rng)) * b.query().surface().face_normal(f);
      const BodyHit hit = b.query().closest(at, 0.05);
      ContactForce probe;
      if (!hit.found() || hit.triangle != f || hit.feature != TriangleFeature::kFace ||
          !b.contact(0, at, Vec3::Zero(), false, probe))
        continue;
      bool same = true;
      for (int d = 0; d < 3 && same; ++d)
        for (double s : {-1e-4, 1e-4}) {
          Vec3 y = at;
          y[d] += s;
          const BodyHit h = b.query().closest(y, 0.05);
          same = same && h.triangle == f && h.feature == TriangleFeature::kFace;
        }
      if (!same) continue;
      Vec3 surface = Vec3::Zero();
      for (int q = 0; q < 3; ++q) surface += hit.barycentric[q] * seg(vel, ch.triangles()(f, q));
      seg(x, placed) = at;
      seg(v, placed) = surface + speed * Vec3(N(rng), N(rng), N(rng));
      ++placed;
    }
    ASSERT_EQ(placed, p);
    const test::TermCheck c = test::check_term(test::TermProbe<FrictionTerm>(*sheet), x, v, 22);
    EXPECT_GT(c.force, 0);
    EXPECT_GT(c.adjoint_x, 0);
    EXPECT_GT(c.adjoint_v, 0);
  }
}

}  // namespace
}  // namespace kf

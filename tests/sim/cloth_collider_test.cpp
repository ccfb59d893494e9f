// Colliders: contact forces and their Jacobians against central finite differences.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>
#include <vector>

#include "sim/cloth/collider.h"

namespace kf {
namespace {

double relative_error(const Mat3& a, const Mat3& fd) {
  const double floor = 1e-6 * fd.cwiseAbs().maxCoeff();
  return ((a - fd).cwiseAbs().array() / fd.cwiseAbs().array().max(floor)).maxCoeff();
}

// Checks the exact Jacobian at x (which must be in contact), that the definite one is NSD, and the
// derivative of the definite one met by two vectors.
void check_contact(const Collider& c, const Vec3& x, const char* what) {
  ContactForce out;
  ASSERT_TRUE(c.contact(0, x, Vec3::Zero(), false, out)) << what << " at " << x.transpose();
  ASSERT_GT(out.f.norm(), 0);
  Mat3 fd;
  const double eps = 1e-7;
  for (int k = 0; k < 3; ++k) {
    Vec3 xp = x, xm = x;
    xp[k] += eps;
    xm[k] -= eps;
    ContactForce p, m;
    ASSERT_TRUE(c.contact(0, xp, Vec3::Zero(), false, p));
    ASSERT_TRUE(c.contact(0, xm, Vec3::Zero(), false, m));
    fd.col(k) = (p.f - m.f) / (2 * eps);
  }
  ASSERT_GT(fd.norm(), 0);
  EXPECT_LT(relative_error(out.dfdx, fd), 1e-5) << what << "\nJ=\n" << out.dfdx << "\nfd=\n" << fd;
  ContactForce def;
  c.contact(0, x, Vec3::Zero(), true, def);
  EXPECT_EQ(def.f, out.f);
  Eigen::SelfAdjointEigenSolver<Mat3> eig(def.dfdx);
  EXPECT_LE(eig.eigenvalues().maxCoeff(), 1e-9) << what;
  const Vec3 w(0.3, -0.7, 0.5), cv(-0.2, 0.4, 0.9);
  const Vec3 dk = c.definite_stiffness_derivative(0, x, w, cv);
  Vec3 fdk;
  for (int k = 0; k < 3; ++k) {
    Vec3 xp = x, xm = x;
    xp[k] += eps;
    xm[k] -= eps;
    ContactForce p, m;
    c.contact(0, xp, Vec3::Zero(), true, p);
    c.contact(0, xm, Vec3::Zero(), true, m);
    fdk[k] = (w.dot(p.dfdx * cv) - w.dot(m.dfdx * cv)) / (2 * eps);
  }
  EXPECT_LT((dk - fdk).norm(), 1e-5 * std::max(fdk.norm(), 1.0)) << what << "\n" << dk.transpose() << "\n"
                                                                   << fdk.transpose();
}

// The whole-cloth form the exact adjoint calls: add_definite_stiffness_derivative at particles placed at
// `points` (some in contact, some not) against central differences of sum_i w_i . Kd(x_i) c_i.
void check_whole_cloth_derivative(const Collider& col, const std::vector<Vec3>& points, const char* what) {
  const int p = int(points.size());
  VecX x(3 * p), w(3 * p), c(3 * p);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int i = 0; i < p; ++i) {
    seg(x, i) = points[size_t(i)];
    seg(w, i) = Vec3(U(rng), U(rng), U(rng));
    seg(c, i) = Vec3(U(rng), U(rng), U(rng));
  }
  auto wKc = [&](const VecX& at) {
    double sum = 0;
    for (int i = 0; i < p; ++i) {
      ContactForce out;
      if (col.contact(0, seg(at, i), Vec3::Zero(), true, out)) sum += seg(w, i).dot(out.dfdx * seg(c, i));
    }
    return sum;
  };
  const double scale = 0.3;
  VecX got = VecX::Zero(3 * p);
  col.add_definite_stiffness_derivative(0, x, w, c, scale, got);
  ASSERT_GT(got.norm(), 0) << what;
  const double eps = 1e-7;
  VecX fd(3 * p);
  for (int k = 0; k < 3 * p; ++k) {
    VecX xp = x, xm = x;
    xp[k] += eps;
    xm[k] -= eps;
    fd[k] = scale * (wKc(xp) - wKc(xm)) / (2 * eps);
  }
  EXPECT_LT((got - fd).norm(), 1e-5 * std::max(fd.norm(), 1.0)) << what << "\n" << got.transpose() << "\n"
                                                                 << fd.transpose();
}

TEST(ContactProfile, StiffnessRisesSmoothlyAndMatchesItsDerivatives) {
  const ContactProfile p{1e4, 0.01};
  double g, dg, ddg, gp, dgp, ddgp, gm, dgm, ddgm;
  p.eval(-1e-3, g, dg, ddg);
  EXPECT_EQ(g + dg + ddg, 0.0);
  p.eval(1e-12, g, dg, ddg);  // where contact begins: no jump in force or stiffness
  EXPECT_LT(g, 1e-15);
  EXPECT_LT(dg, 1e-10);
  p.eval(0.01 * (1 - 1e-9), gm, dgm, ddgm);  // the end of the ramp
  p.eval(0.01 * (1 + 1e-9), gp, dgp, ddgp);
  EXPECT_NEAR(gm, gp, 1e-6);
  EXPECT_NEAR(dgm, dgp, 1e-3);
  EXPECT_NEAR(gp, 1e4 * 0.005, 1e-6);
  for (double d : {0.001, 0.004, 0.0099, 0.02}) {
    const double e = 1e-8;
    p.eval(d, g, dg, ddg);
    p.eval(d + e, gp, dgp, ddgp);
    p.eval(d - e, gm, dgm, ddgm);
    EXPECT_NEAR(dg, (gp - gm) / (2 * e), 1e-5 * 1e4) << d;
    EXPECT_NEAR(ddg, (dgp - dgm) / (2 * e), 1e-5 * 1e6) << d;
    EXPECT_NEAR(g, (p.energy(d + e) - p.energy(d - e)) / (2 * e), 1e-6 * 1e4 * d) << d;
  }
  EXPECT_EQ(p.energy(0.0), 0.0);
  const ContactProfile linear{1e4, 0.0};
  linear.eval(0.003, g, dg, ddg);
  EXPECT_DOUBLE_EQ(g, 30.0);
  EXPECT_DOUBLE_EQ(dg, 1e4);
}

const Vec3 kCenter(0.1, 0.2, -0.3);
const Vec3 kAxis = Vec3(0.2, 1.0, 0.1).normalized();
constexpr double kThickness = 0.02, kStiffness = 1e4, kRamp = 0.5 * kThickness;

const GroundShape kGround{kCenter, kAxis};
const SphereShape kSphere{kCenter, 0.4};
const TorusShape kTorus{kCenter, kAxis, 0.4, 0.05};
const CapsuleShape kCapsule{kCenter, kCenter + Vec3(0.5, 0.3, -0.2), 0.1};

TEST(ClothCollider, GroundJacobianAndSeparation) {
  const GroundShape& s = kGround;
  GroundCollider g(s, kThickness, kStiffness, kRamp);
  check_contact(g, s.point + 0.013 * s.normal + Vec3(0.3, 0, 0.1).cross(s.normal), "ground");
  check_contact(g, s.point - 0.05 * s.normal, "ground (penetrating)");
  check_whole_cloth_derivative(g, {s.point + 0.015 * s.normal, s.point + 0.05 * s.normal, s.point - 0.01 * s.normal},
                               "ground");
  ContactForce out;
  EXPECT_FALSE(g.contact(0, s.point + 0.03 * s.normal, Vec3::Zero(), false, out));
}

TEST(ClothCollider, SphereJacobianMatchesFiniteDifferences) {
  const SphereShape& s = kSphere;
  SphereCollider c(s, kThickness, kStiffness, kRamp);
  std::mt19937 rng(2);
  std::normal_distribution<double> N;
  std::uniform_real_distribution<double> U(-0.9, 0.9);
  for (int t = 0; t < 10; ++t) {
    const Vec3 dir = Vec3(N(rng), N(rng), N(rng)).normalized();
    check_contact(c, s.center + (s.radius + U(rng) * kThickness) * dir, "sphere");
  }
  check_whole_cloth_derivative(c, {s.center + Vec3(0, s.radius + 0.3 * kThickness, 0),
                                   s.center + Vec3(0.2, 0.1, s.radius).normalized() * (s.radius - 0.5 * kThickness),
                                   s.center + Vec3(2 * s.radius, 0, 0)},
                               "sphere");
  ContactForce out;
  EXPECT_FALSE(c.contact(0, s.center + Vec3(0, s.radius + 1.01 * kThickness, 0), Vec3::Zero(), false, out));
  EXPECT_TRUE(c.contact(0, s.center, Vec3::Zero(), false, out));  // dead centre: finite push
  EXPECT_TRUE(out.f.allFinite() && out.dfdx.allFinite());
}

TEST(ClothCollider, TorusJacobianMatchesFiniteDifferences) {
  const TorusShape& s = kTorus;
  TorusCollider c(s, kThickness, kStiffness, kRamp);
  const Vec3 a = s.axis;
  const Vec3 e1 = a.unitOrthogonal(), e2 = a.cross(e1);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> angle(0, 2 * M_PI), U(-0.9, 0.9);
  for (int t = 0; t < 10; ++t) {
    const double th = angle(rng), ps = angle(rng);
    const Vec3 radial = std::cos(th) * e1 + std::sin(th) * e2;
    const double d = s.tube_radius + U(rng) * kThickness;
    check_contact(c, s.center + s.radius * radial + d * (std::cos(ps) * radial + std::sin(ps) * a), "torus");
  }
  check_whole_cloth_derivative(c, {s.center + s.radius * e1 + (s.tube_radius + 0.4 * kThickness) * a,
                                   s.center + s.radius * e2 - (s.tube_radius - 0.3 * kThickness) * e2, s.center},
                               "torus");
  ContactForce out;
  EXPECT_FALSE(c.contact(0, s.center, Vec3::Zero(), false, out));  // the hole of the ring is free
  EXPECT_FALSE(c.contact(0, s.center + 0.3 * a, Vec3::Zero(), false, out));
  // On the tube's centre line and on the axis: finite.
  EXPECT_TRUE(c.contact(0, s.center + s.radius * e1, Vec3::Zero(), false, out));
  EXPECT_TRUE(out.f.allFinite() && out.dfdx.allFinite());
}

TEST(ClothCollider, CapsuleJacobianMatchesFiniteDifferences) {
  const CapsuleShape& s = kCapsule;
  CapsuleCollider c(s, kThickness, kStiffness, kRamp);
  const Vec3 e = (s.b - s.a).normalized(), e1 = e.unitOrthogonal(), e2 = e.cross(e1);
  const double length = (s.b - s.a).norm();
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> angle(0, 2 * M_PI), along(0.05, 0.95), U(-0.9, 0.9), cap(0.1, 1.4);
  for (int t = 0; t < 10; ++t) {  // beside the cylinder, away from the caps' seams
    const double th = angle(rng);
    const Vec3 radial = std::cos(th) * e1 + std::sin(th) * e2;
    check_contact(c, s.a + along(rng) * length * e + (s.radius + U(rng) * kThickness) * radial, "capsule side");
  }
  for (int t = 0; t < 10; ++t) {  // on the caps, beyond either end
    const double th = angle(rng), polar = cap(rng);
    const Vec3 radial = std::cos(th) * e1 + std::sin(th) * e2;
    const Vec3 dir = std::cos(polar) * e + std::sin(polar) * radial;
    const double d = s.radius + U(rng) * kThickness;
    check_contact(c, t % 2 ? Vec3(s.b + d * dir) : Vec3(s.a - d * dir), "capsule cap");
  }
  check_whole_cloth_derivative(c, {s.a + 0.5 * length * e + (s.radius + 0.4 * kThickness) * e1,
                                   s.b + (s.radius + 0.2 * kThickness) * (e + e2).normalized(),
                                   s.a - (s.radius - 0.5 * kThickness) * e, s.a + 0.3 * length * e + 3 * s.radius * e2},
                               "capsule");
  ContactForce out;
  EXPECT_FALSE(c.contact(0, s.a + 0.5 * length * e + (s.radius + 1.01 * kThickness) * e1, Vec3::Zero(), false, out));
  EXPECT_FALSE(c.contact(0, s.b + (s.radius + 1.01 * kThickness) * e, Vec3::Zero(), false, out));
  EXPECT_TRUE(c.contact(0, s.a + 0.5 * length * e, Vec3::Zero(), false, out));  // on the axis: a finite push
  EXPECT_TRUE(out.f.allFinite() && out.dfdx.allFinite());
  EXPECT_NEAR(out.f.dot(e), 0.0, 1e-12);
}

TEST(ClothCollider, FactoryBuildsOnePerSpecAndNoneForNone) {
  EXPECT_TRUE(make_colliders({}, 0.5).empty());
  const auto spec = [](ColliderShape shape) { return ColliderSpec{shape, kThickness, kStiffness}; };
  auto cs = make_colliders({spec(kGround), spec(kSphere), spec(kTorus), spec(kCapsule)}, 0.5);
  ASSERT_EQ(cs.size(), 4u);
  EXPECT_NE(dynamic_cast<TorusCollider*>(cs[2].get()), nullptr);
  EXPECT_NE(dynamic_cast<CapsuleCollider*>(cs[3].get()), nullptr);
}

}  // namespace
}  // namespace kf

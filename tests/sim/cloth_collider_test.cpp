// Colliders: contact forces and their Jacobians against central finite differences.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

#include "sim/cloth/collider.h"

namespace kf {
namespace {

double relative_error(const Mat3& a, const Mat3& fd) {
  const double floor = 1e-6 * fd.cwiseAbs().maxCoeff();
  return ((a - fd).cwiseAbs().array() / fd.cwiseAbs().array().max(floor)).maxCoeff();
}

// Checks the exact Jacobian at x (which must be in contact) and that the definite one is NSD.
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
}

ColliderSpec spec(const std::string& type) {
  ColliderSpec s;
  s.type = type;
  s.center = Vec3(0.1, 0.2, -0.3);
  s.axis = Vec3(0.2, 1.0, 0.1).normalized();
  s.radius = 0.4;
  s.tube_radius = 0.05;
  s.thickness = 0.02;
  s.stiffness = 1e4;
  return s;
}

TEST(ClothCollider, GroundJacobianAndSeparation) {
  const ColliderSpec s = spec("ground");
  GroundCollider g(s);
  check_contact(g, s.center + 0.01 * s.axis + Vec3(0.3, 0, 0.1).cross(s.axis), "ground");
  check_contact(g, s.center - 0.05 * s.axis, "ground (penetrating)");
  ContactForce out;
  EXPECT_FALSE(g.contact(0, s.center + 0.03 * s.axis, Vec3::Zero(), false, out));
}

TEST(ClothCollider, SphereJacobianMatchesFiniteDifferences) {
  const ColliderSpec s = spec("sphere");
  SphereCollider c(s);
  std::mt19937 rng(2);
  std::normal_distribution<double> N;
  std::uniform_real_distribution<double> U(-0.9, 0.9);
  for (int t = 0; t < 10; ++t) {
    const Vec3 dir = Vec3(N(rng), N(rng), N(rng)).normalized();
    check_contact(c, s.center + (s.radius + U(rng) * s.thickness) * dir, "sphere");
  }
  ContactForce out;
  EXPECT_FALSE(c.contact(0, s.center + Vec3(0, s.radius + 1.01 * s.thickness, 0), Vec3::Zero(), false, out));
  EXPECT_TRUE(c.contact(0, s.center, Vec3::Zero(), false, out));  // dead centre: finite push
  EXPECT_TRUE(out.f.allFinite() && out.dfdx.allFinite());
}

TEST(ClothCollider, TorusJacobianMatchesFiniteDifferences) {
  const ColliderSpec s = spec("torus");
  TorusCollider c(s);
  const Vec3 a = s.axis;
  const Vec3 e1 = a.unitOrthogonal(), e2 = a.cross(e1);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> angle(0, 2 * M_PI), U(-0.9, 0.9);
  for (int t = 0; t < 10; ++t) {
    const double th = angle(rng), ps = angle(rng);
    const Vec3 radial = std::cos(th) * e1 + std::sin(th) * e2;
    const double d = s.tube_radius + U(rng) * s.thickness;
    check_contact(c, s.center + s.radius * radial + d * (std::cos(ps) * radial + std::sin(ps) * a), "torus");
  }
  ContactForce out;
  EXPECT_FALSE(c.contact(0, s.center, Vec3::Zero(), false, out));  // the hole of the ring is free
  EXPECT_FALSE(c.contact(0, s.center + 0.3 * a, Vec3::Zero(), false, out));
  // On the tube's centre line and on the axis: finite.
  EXPECT_TRUE(c.contact(0, s.center + s.radius * e1, Vec3::Zero(), false, out));
  EXPECT_TRUE(out.f.allFinite() && out.dfdx.allFinite());
}

TEST(ClothCollider, FactoryBuildsOnePerSpecAndNoneForNone) {
  EXPECT_TRUE(make_colliders({}).empty());
  auto cs = make_colliders({spec("ground"), spec("sphere"), spec("torus")});
  ASSERT_EQ(cs.size(), 3u);
  EXPECT_NE(dynamic_cast<TorusCollider*>(cs[2].get()), nullptr);
}

}  // namespace
}  // namespace kf

// Colliders: contact forces and their Jacobians against central finite differences.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>
#include <string>
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

// The exact Jacobian at x (in contact) against central differences at two steps that agree with each
// other and with it to 1e-6 of its size; the definite Jacobian NSD; the definite one's derivative.
void check_contact_two_steps(const Collider& c, const Vec3& x, const std::string& what) {
  ContactForce out;
  ASSERT_TRUE(c.contact(0, x, Vec3::Zero(), false, out)) << what << " at " << x.transpose();
  ASSERT_GT(out.f.norm(), 0) << what;
  Mat3 fd[2];
  const double steps[2] = {1e-6, 2e-7};
  for (int s = 0; s < 2; ++s)
    for (int k = 0; k < 3; ++k) {
      Vec3 xp = x, xm = x;
      xp[k] += steps[s];
      xm[k] -= steps[s];
      ContactForce p, m;
      ASSERT_TRUE(c.contact(0, xp, Vec3::Zero(), false, p) && c.contact(0, xm, Vec3::Zero(), false, m)) << what;
      fd[s].col(k) = (p.f - m.f) / (2 * steps[s]);
    }
  const double size = fd[0].norm();
  ASSERT_GT(size, 0) << what;
  EXPECT_LE((fd[0] - fd[1]).norm(), 1e-6 * size) << what << ": the two steps disagree";
  EXPECT_LE((out.dfdx - fd[0]).norm(), 1e-6 * size) << what << "\nJ=\n" << out.dfdx << "\nfd=\n" << fd[0];
  check_contact(c, x, what.c_str());
}

// A point at signed distance `depth` from a distance collider's surface: walk from `start` along its normal.
Vec3 at_depth(const DistanceCollider& c, Vec3 x, double depth) {
  for (int it = 0; it < 3; ++it) {  // once is exact where the nearest point does not change; repeat for safety
    double phi;
    Vec3 n;
    Mat3 dn;
    c.distance(x, phi, n, dn);
    x -= (phi - depth) * n;
  }
  return x;
}

const BoxShape kBox{kCenter, Vec3(0.8, 0.3, 0.5), Vec3(1, 0.2, -0.1).normalized(),
                    (kAxis - kAxis.dot(Vec3(1, 0.2, -0.1).normalized()) * Vec3(1, 0.2, -0.1).normalized()).normalized(),
                    0.05};
const RectangleShape kRectangle{kCenter, kBox.u_axis, kBox.v_axis, 0.6, 0.4};

Mat3 axes_of(const Vec3& u, const Vec3& v) {
  Mat3 r;
  r << u, v, u.cross(v);
  return r;
}

TEST(ClothCollider, BoxJacobianMatchesFiniteDifferencesOnFacesEdgesAndCorners) {
  const BoxShape& s = kBox;
  BoxCollider c(s, kThickness, kStiffness, kRamp);
  const Mat3 axes = axes_of(s.u_axis, s.v_axis);
  const Vec3 half = 0.5 * s.size - Vec3::Constant(s.radius);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> U(-0.8, 0.8), depth(-0.9 * kThickness, 0.9 * kThickness);
  int checked = 0;
  // Every face (one sign), edge (two) and corner (three), from outside and from inside the surface.
  for (int a = -1; a <= 1; ++a)
    for (int b = -1; b <= 1; ++b)
      for (int d = -1; d <= 1; ++d) {
        if (a == 0 && b == 0 && d == 0) continue;
        const Vec3 sign(a, b, d);
        for (int t = 0; t < 2; ++t) {
          Vec3 q;
          for (int k = 0; k < 3; ++k) q[k] = sign[k] != 0 ? sign[k] * (half[k] + 0.1) : U(rng) * half[k];
          const Vec3 x = at_depth(c, s.center + axes * q, depth(rng));
          check_contact_two_steps(c, x, "box region " + std::to_string(a) + "," + std::to_string(b) + "," +
                                            std::to_string(d));
          ++checked;
        }
      }
  EXPECT_EQ(checked, 52);
  check_whole_cloth_derivative(c, {at_depth(c, s.center + axes * Vec3(0, 1, 0), 0.4 * kThickness),
                                   at_depth(c, s.center + axes * Vec3(1, 1, 0), -0.3 * kThickness),
                                   at_depth(c, s.center + axes * Vec3(1, 1, 1), 0.7 * kThickness),
                                   s.center + axes * Vec3(0, 2, 0)},
                               "box");
  // Out of reach beyond the thickness; deep inside (past the rounding) a finite push out of the nearest face.
  ContactForce out;
  EXPECT_FALSE(c.contact(0, at_depth(c, s.center + axes * Vec3(1, 1, 1), 1.01 * kThickness), Vec3::Zero(), false, out));
  ASSERT_TRUE(c.contact(0, s.center + axes * Vec3(0, 0.5 * s.size.y() - 0.06, 0), Vec3::Zero(), false, out));
  EXPECT_TRUE(out.f.allFinite() && out.dfdx.allFinite());
  EXPECT_GT(out.f.dot(axes.col(1)), 0);
  // Round an edge the normal turns continuously from one face's to the other's.
  double phi;
  Vec3 n0, n1;
  Mat3 dn;
  c.distance(s.center + axes * Vec3(half.x() - 1e-9, half.y() + s.radius, 0), phi, n0, dn);
  c.distance(s.center + axes * Vec3(half.x() + 1e-9, half.y() + s.radius, 0), phi, n1, dn);
  EXPECT_LT((n0 - n1).norm(), 1e-6);
  EXPECT_NEAR(phi, 0.0, 1e-9);
}

TEST(ClothCollider, RectangleJacobianMatchesFiniteDifferencesOnBothSidesAndRoundItsEdges) {
  const RectangleShape& s = kRectangle;
  BoxCollider c(s, kThickness, kStiffness, kRamp);
  const Mat3 axes = axes_of(s.u_axis, s.v_axis);
  const Vec3 half(0.5 * s.width, 0.5 * s.height, 0);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> U(-0.8, 0.8), depth(0.1 * kThickness, 0.9 * kThickness);
  int checked = 0;
  for (int a = -1; a <= 1; ++a)
    for (int b = -1; b <= 1; ++b)
      for (int side : {-1, 1}) {
        Vec3 q;
        q[0] = a != 0 ? a * (half[0] + 0.05) : U(rng) * half[0];
        q[1] = b != 0 ? b * (half[1] + 0.05) : U(rng) * half[1];
        q[2] = side * 0.05;
        const Vec3 x = at_depth(c, s.center + axes * q, depth(rng));
        check_contact_two_steps(c, x, "rectangle region " + std::to_string(a) + "," + std::to_string(b) + " side " +
                                          std::to_string(side));
        ++checked;
      }
  EXPECT_EQ(checked, 18);
  check_whole_cloth_derivative(c, {s.center + axes * Vec3(0.1, 0.05, 0.4 * kThickness),
                                   s.center + axes * Vec3(0.1, -0.05, -0.6 * kThickness),
                                   s.center + axes * Vec3(half.x() + 0.005, 0, 0.01),
                                   s.center + axes * Vec3(0, 0, 3 * kThickness)},
                               "rectangle");
  // Within its footprint it pushes along its normal away from the side the particle is on; beyond its edge
  // it does not reach a particle farther than the thickness; in its plane, a finite push.
  ContactForce out;
  ASSERT_TRUE(c.contact(0, s.center + axes * Vec3(0.1, 0.1, -0.5 * kThickness), Vec3::Zero(), false, out));
  EXPECT_LT(out.f.dot(axes.col(2)), 0);
  EXPECT_NEAR(out.f.cross(axes.col(2)).norm(), 0.0, 1e-9);
  EXPECT_FALSE(c.contact(0, s.center + axes * Vec3(half.x() + 1.01 * kThickness, 0, 0), Vec3::Zero(), false, out));
  ASSERT_TRUE(c.contact(0, s.center + axes * Vec3(0.1, 0.1, 0), Vec3::Zero(), false, out));
  EXPECT_TRUE(out.f.allFinite() && out.dfdx.allFinite());
}

TEST(ClothCollider, FactoryBuildsOnePerSpecAndNoneForNone) {
  EXPECT_TRUE(make_colliders({}, 0.5).empty());
  const auto spec = [](ColliderShape shape) { return ColliderSpec{shape, kThickness, kStiffness}; };
  auto cs = make_colliders({spec(kGround), spec(kSphere), spec(kTorus), spec(kCapsule), spec(kBox), spec(kRectangle)}, 0.5);
  ASSERT_EQ(cs.size(), 6u);
  EXPECT_NE(dynamic_cast<BoxCollider*>(cs[4].get()), nullptr);
  EXPECT_NE(dynamic_cast<BoxCollider*>(cs[5].get()), nullptr);
  EXPECT_NE(dynamic_cast<TorusCollider*>(cs[2].get()), nullptr);
  EXPECT_NE(dynamic_cast<CapsuleCollider*>(cs[3].get()), nullptr);
}

}  // namespace
}  // namespace kf

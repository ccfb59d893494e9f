// Cape colliders: self-collision pairs and the moving body, forces and Jacobians against central differences.
#include <gtest/gtest.h>

#include <random>

#include "sim/cape/body_collider.h"
#include "sim/cape/self_collider.h"
#include "sim/character/character.h"
#include "character_test_util.h"

namespace kf {
namespace {

// S(x) = sum_j w_j . f_j(x): its gradient in x_i is (df_i/dx_i)^T w_i (contact) plus the cross blocks
// (add_cross_transpose with scale 1). Both pieces are checked at once against central differences of S.
// Then the derivative of the definite stiffness, d/dx sum_i w_i . Kd_i(x) c_i, the same way.
TEST(SelfCollider, ForceGradientWithCrossBlocksMatchesFiniteDifferences) {
  const int p = 5;
  const double thickness = 0.05, k = 300.0;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  VecX x(3 * p), w(3 * p);
  for (int i = 0; i < 3 * p; ++i) {
    x[i] = 0.02 * u(rng);
    w[i] = u(rng);
  }
  SelfCollider self(p, thickness, k, 0.5 * thickness);
  VecX c(3 * p);
  for (int i = 0; i < 3 * p; ++i) c[i] = u(rng);
  auto S = [&](const VecX& y) {
    self.update(y);
    double s = 0;
    for (int i = 0; i < p; ++i) {
      ContactForce c;
      if (self.contact(0, seg(y, i), Vec3::Zero(), false, c)) s += seg(w, i).dot(c.f);
    }
    return s;
  };
  self.update(x);
  VecX grad = VecX::Zero(3 * p);
  int in_contact = 0;
  for (int i = 0; i < p; ++i) {
    ContactForce c;
    if (self.contact(0, seg(x, i), Vec3::Zero(), false, c)) {
      seg(grad, i) = c.dfdx.transpose() * seg(w, i);
      ++in_contact;
    }
  }
  self.add_cross_transpose(0, w, 1.0, grad);
  VecX dK = VecX::Zero(3 * p);
  self.add_definite_stiffness_derivative(0, x, w, c, 1.0, dK);
  ASSERT_EQ(in_contact, p);
  ASSERT_GT(grad.norm(), 1.0);
  ASSERT_GT(dK.norm(), 1.0);
  auto Q = [&](const VecX& y) {  // sum_i w_i . Kd_i(y) c_i
    self.update(y);
    double s = 0;
    for (int i = 0; i < p; ++i) {
      ContactForce f;
      if (self.contact(0, seg(y, i), Vec3::Zero(), true, f)) s += seg(w, i).dot(f.dfdx * seg(c, i));
    }
    return s;
  };
  const double eps = 1e-6, floor = 1e-6 * grad.cwiseAbs().maxCoeff(), floor_k = 1e-6 * dK.cwiseAbs().maxCoeff();
  for (int k3 = 0; k3 < 3 * p; ++k3) {
    VecX a = x, b = x;
    a[k3] += eps;
    b[k3] -= eps;
    const double fd = (S(a) - S(b)) / (2 * eps), fdk = (Q(a) - Q(b)) / (2 * eps);
    EXPECT_LT(std::abs(fd - grad[k3]) / std::max(std::abs(fd), floor), 1e-5) << k3 << ": " << fd << " vs " << grad[k3];
    EXPECT_LT(std::abs(fdk - dK[k3]) / std::max(std::abs(fdk), floor_k), 1e-5) << k3 << ": " << fdk << " vs " << dK[k3];
  }
}

TEST(SelfCollider, IgnoresFarPairsAndItself) {
  SelfCollider self(2, 0.01, 100.0, 0.0);  // linear penalty
  VecX x(6);
  x << 0, 0, 0, 0.02, 0, 0;
  self.update(x);
  ContactForce c;
  EXPECT_FALSE(self.contact(0, seg(x, 0), Vec3::Zero(), false, c));
  x[3] = 0.004;
  self.update(x);
  ASSERT_TRUE(self.contact(0, seg(x, 0), Vec3::Zero(), false, c));
  EXPECT_NEAR(c.f.x(), -100.0 * 0.006, 1e-12);  // pushed away from particle 1
  EXPECT_NEAR(c.f.tail<2>().norm(), 0.0, 1e-15);
}

// Points just outside and just inside face centres of the posed body: force along the outward normal and
// df/dx against central differences.
TEST(BodyCollider, ContactForceJacobianMatchesFiniteDifferences) {
  Character ch(test::character_asset());
  VecX pose;
  ch.pose(1.5, pose);
  const double thickness = 0.01, k = 2000.0;
  BodyCollider body(ch.triangles(), ch.vertex_count(), thickness, k, 0.05, 0.5 * thickness);
  body.set_pose(pose);
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> pick(0, ch.triangle_count() - 1);
  int checked = 0;
  for (int trial = 0; trial < 60 && checked < 12; ++trial) {
    const int f = pick(rng);
    const Vec3 a = seg(pose, ch.triangles()(f, 0)), b = seg(pose, ch.triangles()(f, 1)), c = seg(pose, ch.triangles()(f, 2));
    const Vec3 n = body.query().surface().face_normal(f);
    const Vec3 x = (a + b + c) / 3 + (trial % 2 ? 0.004 : -0.003) * n;
    ContactForce out;
    if (!body.contact(0, x, Vec3::Zero(), false, out)) continue;
    const BodyHit hit = body.query().closest(x, 0.05);
    if (hit.triangle != f) continue;  // another part of the body is closer: not this face's check
    ASSERT_GT(out.f.norm(), 0.0);
    EXPECT_GT(out.f.dot(n), 0.0);  // pushes outward
    const double eps = 1e-6;
    for (int d = 0; d < 3; ++d) {
      Vec3 xp = x, xm = x;
      xp[d] += eps;
      xm[d] -= eps;
      ContactForce fp, fm;
      ASSERT_TRUE(body.contact(0, xp, Vec3::Zero(), false, fp));
      ASSERT_TRUE(body.contact(0, xm, Vec3::Zero(), false, fm));
      const Vec3 fd = (fp.f - fm.f) / (2 * eps);
      EXPECT_LT((fd - out.dfdx.col(d)).norm(), 1e-5 * out.dfdx.norm()) << "face " << f << " axis " << d;
      // The definite stiffness's derivative met by two vectors.
      const Vec3 wv(0.3, -0.7, 0.5), cv(-0.2, 0.4, 0.9);
      ContactForce kp, km;
      body.contact(0, xp, Vec3::Zero(), true, kp);
      body.contact(0, xm, Vec3::Zero(), true, km);
      const double fdk = (wv.dot(kp.dfdx * cv) - wv.dot(km.dfdx * cv)) / (2 * eps);
      const double dk = body.definite_stiffness_derivative(0, x, wv, cv)[d];
      EXPECT_LT(std::abs(fdk - dk), 1e-5 * k / thickness + 1e-6 * std::abs(fdk)) << "face " << f << " axis " << d;
    }
    ++checked;
  }
  EXPECT_GE(checked, 6);
}

}  // namespace
}  // namespace kf

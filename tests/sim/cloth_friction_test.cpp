// Friction: the smoothed Coulomb force of one contact and every derivative the linearised step and its exact
// adjoint use, on its own and inside each collider (analytic shapes, the character's body, self contact),
// against central differences at two steps, in the sticking (slip << eps), transition and sliding
// (slip >> eps) regimes. Each check first asserts the derivative is not zero.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "sim/cape/body_collider.h"
#include "sim/cape/self_collider.h"
#include "sim/character/character.h"
#include "sim/cloth/collider.h"
#include "sim/cloth/friction.h"
#include "character_test_util.h"

namespace kf {
namespace {

using Fn = std::function<VecX(const VecX&)>;

// J (m x n) against central differences of f at x0 with steps eps and eps / 4: both must agree with J to
// tol relative to the largest entry of the difference quotient (so the two steps also agree).
void expect_jacobian(const Fn& f, const VecX& x0, const MatX& J, double eps, const std::string& what,
                     double tol = 1e-6) {
  for (double e : {eps, 0.25 * eps}) {
    MatX fd(J.rows(), J.cols());
    for (int k = 0; k < int(x0.size()); ++k) {
      VecX xp = x0, xm = x0;
      xp[k] += e;
      xm[k] -= e;
      fd.col(k) = (f(xp) - f(xm)) / (2 * e);
    }
    const double scale = fd.cwiseAbs().maxCoeff();
    ASSERT_GT(scale, 0) << what;
    ASSERT_GT(J.cwiseAbs().maxCoeff(), 0) << what;
    EXPECT_LE((J - fd).cwiseAbs().maxCoeff(), tol * scale)
        << what << " (step " << e << ")\nanalytic\n" << J << "\ndifferences\n" << fd;
  }
}

VecX v3(const Vec3& a) { return VecX(a); }
MatX row(const Vec3& a) { return MatX(a.transpose()); }

const Vec3 kA(0.3, -0.7, 0.5), kB(-0.2, 0.4, 0.9);  // the vectors w, c the adjoint meets D with

// Slip speeds of the three regimes for eps = 0.01 m/s.
constexpr double kEps = 0.01;
const double kSlips[] = {1e-4, 0.012, 0.3};

TEST(Friction, ForceDerivativesMatchFiniteDifferences) {
  const Vec3 n = Vec3(0.2, 1.0, -0.3).normalized();
  const Vec3 dir = Vec3(1.0, 0.1, 0.4).cross(n).normalized();
  const double L = 0.7;
  for (double slip : kSlips) {
    const Vec3 u = slip * dir + 0.05 * n;  // a normal part too: it must not count
    const FrictionForce F = friction_force(L, n, u, kEps);
    const std::string at = "slip " + std::to_string(slip);
    expect_jacobian([&](const VecX& y) { return v3(friction_force(L, n, y, kEps).f); }, u, F.dfdu, 1e-4 * kEps,
                    "df/du " + at);
    expect_jacobian([&](const VecX& y) { return v3(friction_force(y[0], n, u, kEps).f); }, VecX::Constant(1, L),
                    MatX(F.dfdL), 1e-4, "df/dL " + at);
    expect_jacobian([&](const VecX& y) { return v3(friction_force(L, y, u, kEps).f); }, n, F.dfdn, 1e-4,
                    "df/dn " + at);
    // Against the slip, at most L, and a damping block the implicit matrix can hold.
    EXPECT_LT(F.f.dot(dir), 0) << at;
    EXPECT_LE(F.f.norm(), L) << at;
    EXPECT_NEAR(F.f.dot(n), 0, 1e-15) << at;
    EXPECT_EQ(F.dfdu, F.dfdu.transpose()) << at;
    EXPECT_LE(Eigen::SelfAdjointEigenSolver<Mat3>(F.dfdu).eigenvalues().maxCoeff(), 1e-12) << at;
    // The step's block is the drag coefficient at u: f = D u, symmetric and negative semi-definite.
    EXPECT_LE((F.damping * u - F.f).norm(), 1e-14 * L) << at;
    EXPECT_EQ(F.damping, F.damping.transpose()) << at;
    EXPECT_LE(Eigen::SelfAdjointEigenSolver<Mat3>(F.damping).eigenvalues().maxCoeff(), 1e-12) << at;
  }
  // Sliding fast: Coulomb's magnitude. Sticking: a viscous drag L / eps.
  EXPECT_NEAR(friction_force(L, n, 100 * dir, kEps).f.norm(), L, 1e-8 * L);
  EXPECT_NEAR(friction_force(L, n, 1e-6 * dir, kEps).f.norm(), L / kEps * 1e-6, 1e-9);
  EXPECT_EQ(friction_force(L, n, Vec3::Zero(), kEps).f, Vec3::Zero());
}

// One particle sliding on a still surface, friction its only force, stepped as the cloth steps it:
// (m - h D) dv = h f. Its slip after the step keeps its direction and shrinks, and the map from slip before
// to slip after has slope at most 1, so nearby runs do not part; with df/du as D (at h mu g = 0.11 m/s,
// ten times eps) the slip overshot zero with slope up to 2.5.
TEST(Friction, StepShrinksSlipWithoutReversingIt) {
  const Vec3 n = Vec3(0.1, 1.0, 0.2).normalized();
  const Vec3 dir = Vec3(1.0, 0.0, 0.3).cross(n).normalized();
  const double m = 0.003, h = 1.0 / 30, L = 0.33 * m * 9.81;
  auto slip_after = [&](double slip) {
    const Vec3 u = slip * dir;
    const FrictionForce F = friction_force(L, n, u, kEps);
    const Vec3 dv = (m * Mat3::Identity() - h * F.damping).ldlt().solve(h * F.f);
    return (u + dv).dot(dir);
  };
  double steepest = 0;
  for (double slip = 1e-4; slip < 2.0; slip *= 1.05) {
    const double after = slip_after(slip), d = 1e-3 * slip;
    EXPECT_GE(after, 0) << "slip " << slip;
    EXPECT_LT(after, slip) << "slip " << slip;
    steepest = std::max(steepest, (slip_after(slip + d) - slip_after(slip - d)) / (2 * d));
  }
  EXPECT_LE(steepest, 1.0);
  EXPECT_GT(steepest, 0.5);  // a fast slide keeps most of its slip
}

TEST(Friction, DampingDerivativeMatchesFiniteDifferences) {
  const Vec3 n = Vec3(-0.4, 1.0, 0.2).normalized();
  const Vec3 dir = Vec3(0.3, 0.2, 1.0).cross(n).normalized();
  const double L = 0.4;
  auto G = [&](double l, const Vec3& nn, const Vec3& uu) { return kA.dot(friction_force(l, nn, uu, kEps).damping * kB); };
  for (double slip : kSlips) {
    const Vec3 u = slip * dir - 0.02 * n;
    const FrictionDampingDerivative d = friction_damping_derivative(L, n, u, kEps, kA, kB);
    const std::string at = "slip " + std::to_string(slip);
    expect_jacobian([&](const VecX& y) { return VecX::Constant(1, G(L, n, y)); }, u, row(d.du), 1e-4 * kEps,
                    "d/du " + at);
    expect_jacobian([&](const VecX& y) { return VecX::Constant(1, G(y[0], n, u)); }, VecX::Constant(1, L),
                    MatX::Constant(1, 1, d.dL), 1e-4, "d/dL " + at);
    expect_jacobian([&](const VecX& y) { return VecX::Constant(1, G(L, y, u)); }, n, row(d.dn), 1e-4, "d/dn " + at);
  }
}

// A collider's friction at particle position x moving with v: the exact df/dx and df/dv, and d/dx, d/dv of
// w . D(x, v) c, against central differences. x must be in contact.
void check_friction(const Collider& col, const Vec3& x, const Vec3& v, const std::string& what) {
  ContactForce out;
  ASSERT_TRUE(col.friction(0, x, v, true, out)) << what;
  auto force = [&](const Vec3& y, const Vec3& vel, bool exact) {
    ContactForce c;
    EXPECT_TRUE(col.friction(0, y, vel, exact, c)) << what;
    return c;
  };
  expect_jacobian([&](const VecX& y) { return v3(force(y, v, false).f); }, x, out.dfdx, 1e-7, what + ": df/dx");
  expect_jacobian([&](const VecX& y) { return v3(force(x, y, false).f); }, v, Mat3(out.dfdv + out.dfdv_rest),
                  1e-4 * kEps, what + ": df/dv");
  const ContactForce def = force(x, v, false);
  EXPECT_EQ(def.f, out.f) << what;
  EXPECT_EQ(def.dfdv, out.dfdv) << what;  // the damping block is the same, exact or not
  EXPECT_EQ(def.dfdx, Mat3::Zero()) << what;
  EXPECT_EQ(def.dfdv_rest, Mat3::Zero()) << what;
  Vec3 ddx, ddv;
  col.damping_derivative(0, x, v, kA, kB, ddx, ddv);
  auto wDc = [&](const Vec3& y, const Vec3& vel) { return VecX::Constant(1, kA.dot(force(y, vel, false).dfdv * kB)); };
  expect_jacobian([&](const VecX& y) { return wDc(y, v); }, x, row(ddx), 1e-7, what + ": d(w.Dc)/dx");
  expect_jacobian([&](const VecX& y) { return wDc(x, y); }, v, row(ddv), 1e-4 * kEps, what + ": d(w.Dc)/dv");
}

constexpr double kThickness = 0.02, kStiffness = 1e4, kRamp = 0.5 * kThickness;
const Vec3 kCenter(0.1, 0.2, -0.3);
const Vec3 kAxis = Vec3(0.2, 1.0, 0.1).normalized();

// Velocities with tangential slip of each regime plus a normal part, at a contact with normal n.
std::vector<Vec3> slip_velocities(const Vec3& n, std::mt19937& rng) {
  std::normal_distribution<double> N;
  std::vector<Vec3> out;
  for (double slip : kSlips) {
    Vec3 t = Vec3(N(rng), N(rng), N(rng));
    t = (t - t.dot(n) * n).normalized();
    out.push_back(slip * t + 0.1 * N(rng) * n);
  }
  return out;
}

TEST(Friction, AnalyticCollidersMatchFiniteDifferences) {
  std::vector<std::unique_ptr<Collider>> cols;
  cols.push_back(std::make_unique<GroundCollider>(GroundShape{kCenter, kAxis}, kThickness, kStiffness, kRamp));
  cols.push_back(std::make_unique<SphereCollider>(SphereShape{kCenter, 0.4}, kThickness, kStiffness, kRamp));
  cols.push_back(std::make_unique<TorusCollider>(TorusShape{kCenter, kAxis, 0.4, 0.05}, kThickness, kStiffness, kRamp));
  cols.push_back(std::make_unique<CapsuleCollider>(CapsuleShape{kCenter, kCenter + Vec3(0.5, 0.3, -0.2), 0.1},
                                                   kThickness, kStiffness, kRamp));
  const Vec3 u = Vec3(1, 0.2, -0.1).normalized(), v = (kAxis - kAxis.dot(u) * u).normalized();
  cols.push_back(std::make_unique<BoxCollider>(BoxShape{kCenter, Vec3(0.8, 0.3, 0.5), u, v, 0.05}, kThickness,
                                               kStiffness, kRamp));
  cols.push_back(std::make_unique<BoxCollider>(RectangleShape{kCenter, u, v, 0.6, 0.4}, kThickness, kStiffness, kRamp));
  const char* names[] = {"ground", "sphere", "torus", "capsule", "box", "rectangle"};
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-0.9, 0.9);
  for (size_t k = 0; k < cols.size(); ++k) {
    Collider& c = *cols[k];
    c.set_friction({0.4, kEps});
    // Points on the surface by walking in from outside along the collider's own normal.
    int checked = 0;
    for (int t = 0; t < 40 && checked < 4; ++t) {
      std::normal_distribution<double> N;
      Vec3 x = kCenter + 0.45 * Vec3(N(rng), N(rng), N(rng)).normalized();
      auto& dc = static_cast<DistanceCollider&>(c);
      double phi;
      Vec3 n;
      Mat3 dn;
      dc.distance(x, phi, n, dn);
      x -= (phi - (0.5 + 0.4 * U(rng)) * kThickness) * n;  // depth within the thickness, on both sides of the ramp
      dc.distance(x, phi, n, dn);
      if (phi >= kThickness || phi < -kThickness) continue;
      for (const Vec3& v : slip_velocities(n, rng))
        check_friction(c, x, v, std::string(names[k]) + " slip " + std::to_string((v - v.dot(n) * n).norm()));
      ++checked;
    }
    EXPECT_GE(checked, 4) << names[k];
  }
}

TEST(Friction, NoneWithoutCoefficientOrContact) {
  SphereCollider c(SphereShape{kCenter, 0.4}, kThickness, kStiffness, kRamp);
  ContactForce out;
  const Vec3 on = kCenter + Vec3(0, 0.4 + 0.3 * kThickness, 0), v(0.2, 0, 0.1);
  EXPECT_FALSE(c.friction(0, on, v, true, out));  // frictionless unless set
  c.set_friction({0.5, kEps});
  ASSERT_TRUE(c.friction(0, on, v, true, out));
  EXPECT_LT(out.f.dot(v), 0);
  EXPECT_FALSE(c.friction(0, kCenter + Vec3(0, 0.4 + 1.01 * kThickness, 0), v, true, out));
  // The contact force itself is unchanged by friction.
  ContactForce with, without;
  c.contact(0, on, v, false, with);
  SphereCollider plain(SphereShape{kCenter, 0.4}, kThickness, kStiffness, kRamp);
  plain.contact(0, on, v, false, without);
  EXPECT_EQ(with.f, without.f);
  EXPECT_EQ(with.dfdv, Mat3::Zero());
}

// Self contact: every particle's friction and damping block come from its pairs, with cross blocks. With
// S = sum_i w_i . f_i(x, v): dS/dx = friction dfdx^T w + the coupled x part, dS/dv = dfdv^T w + the coupled
// v part (add_friction_coupled, not exact); with Q = sum_i w_i . D_i(x, v) c_i: dQ/dx, dQ/dv = what the
// exact add_friction_coupled adds beyond that.
TEST(Friction, SelfContactMatchesFiniteDifferences) {
  const int p = 5;
  const double thickness = 0.05, k = 300.0;
  for (double slip : kSlips) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> U(-1, 1);
    VecX x(3 * p), v(3 * p), w(3 * p), c(3 * p);
    for (int i = 0; i < 3 * p; ++i) {
      x[i] = 0.02 * U(rng);
      v[i] = slip * U(rng);
      w[i] = U(rng);
      c[i] = U(rng);
    }
    SelfCollider self(p, thickness, k, 0.5 * thickness);
    self.set_friction({0.4, kEps});
    const std::string at = "slip scale " + std::to_string(slip);
    auto S = [&](const VecX& y, const VecX& vel) {
      self.update(y, vel);
      double s = 0;
      for (int i = 0; i < p; ++i) {
        ContactForce f;
        if (self.friction(0, seg(y, i), seg(vel, i), false, f)) s += seg(w, i).dot(f.f);
      }
      return VecX::Constant(1, s);
    };
    auto Q = [&](const VecX& y, const VecX& vel) {
      self.update(y, vel);
      double s = 0;
      for (int i = 0; i < p; ++i) {
        ContactForce f;
        if (self.friction(0, seg(y, i), seg(vel, i), false, f)) s += seg(w, i).dot(f.dfdv * seg(c, i));
      }
      return VecX::Constant(1, s);
    };
    self.update(x, v);
    VecX gx = VecX::Zero(3 * p), gv = VecX::Zero(3 * p), qx = VecX::Zero(3 * p), qv = VecX::Zero(3 * p);
    int in_contact = 0;
    for (int i = 0; i < p; ++i) {
      ContactForce f;
      if (!self.friction(0, seg(x, i), seg(v, i), true, f)) continue;
      ++in_contact;
      seg(gx, i) = f.dfdx.transpose() * seg(w, i);
      seg(gv, i) = (f.dfdv + f.dfdv_rest).transpose() * seg(w, i);
    }
    ASSERT_EQ(in_contact, p);
    self.add_friction_coupled(0, w, c, 1.0, false, gx, gv);
    self.add_friction_coupled(0, w, c, 1.0, true, qx, qv);
    VecX cx = VecX::Zero(3 * p), cv = VecX::Zero(3 * p);
    self.add_friction_coupled(0, w, c, 1.0, false, cx, cv);
    qx -= cx;
    qv -= cv;
    expect_jacobian([&](const VecX& y) { return S(y, v); }, x, MatX(gx.transpose()), 1e-7, "dS/dx " + at);
    expect_jacobian([&](const VecX& y) { return S(x, y); }, v, MatX(gv.transpose()), 1e-4 * kEps, "dS/dv " + at);
    expect_jacobian([&](const VecX& y) { return Q(y, v); }, x, MatX(qx.transpose()), 1e-7, "dQ/dx " + at);
    expect_jacobian([&](const VecX& y) { return Q(x, y); }, v, MatX(qv.transpose()), 1e-4 * kEps, "dQ/dv " + at);
  }
}

// The moving body: slip relative to the surface's velocity at the closest point, which slides with x
// (faces, edges and vertices of the posed character). In the BodyCollider suite: Embree runs untrapped.
TEST(BodyCollider, FrictionMatchesFiniteDifferences) {
  Character ch(test::character_asset());
  VecX pose, next;
  ch.pose(1.5, pose);
  ch.pose(1.5 + 1.0 / 30, next);
  const double thickness = 0.01, k = 2000.0;
  BodyCollider body(ch.triangles(), ch.vertex_count(), thickness, k, 0.05, 0.5 * thickness);
  body.set_pose(pose);
  const VecX vel = (next - pose) * 30.0;
  body.set_velocity(vel);
  body.set_friction({0.5, kEps});
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> pick(0, ch.triangle_count() - 1);
  std::uniform_real_distribution<double> U(0, 1);
  int checked[3] = {0, 0, 0};  // face, edge, vertex
  for (int trial = 0; trial < 600 && (checked[0] < 4 || checked[1] < 3 || checked[2] < 2); ++trial) {
    const int f = pick(rng);
    const Vec3 a = seg(pose, ch.triangles()(f, 0)), b = seg(pose, ch.triangles()(f, 1)), c = seg(pose, ch.triangles()(f, 2));
    const Vec3 n = body.query().surface().face_normal(f);
    const int kind = trial % 3;
    // Beyond an edge or a vertex (outward and sideways) the closest point is that feature.
    const Vec3 base = kind == 0 ? Vec3((a + b + c) / 3) : kind == 1 ? Vec3(0.5 * (a + b)) : a;
    const Vec3 out_side = kind == 0 ? Vec3::Zero() : kind == 1 ? Vec3((0.5 * (a + b) - c).normalized()) : Vec3((a - 0.5 * (b + c)).normalized());
    const Vec3 x = base + (0.002 + 0.005 * U(rng)) * n + 0.002 * out_side;
    const BodyHit hit = body.query().closest(x, 0.05);
    ContactForce probe;
    if (!hit.found() || !body.contact(0, x, Vec3::Zero(), false, probe)) continue;
    const int got = hit.feature == TriangleFeature::kFace ? 0
                    : (hit.feature == TriangleFeature::kEdgeAB || hit.feature == TriangleFeature::kEdgeBC ||
                       hit.feature == TriangleFeature::kEdgeCA)
                        ? 1
                        : 2;
    // The differences must stay on one feature of one triangle.
    bool same = true;
    for (int d = 0; d < 3 && same; ++d)
      for (double s : {-1e-4, 1e-4}) {
        Vec3 y = x;
        y[d] += s;
        const BodyHit h = body.query().closest(y, 0.05);
        same = same && h.triangle == hit.triangle && h.feature == hit.feature;
      }
    if (!same || checked[got] >= 4) continue;
    const Vec3 nn = hit.normal;
    std::vector<Vec3> vs = slip_velocities(nn, rng);
    Vec3 vb = Vec3::Zero();
    for (int q = 0; q < 3; ++q) vb += hit.barycentric[q] * seg(vel, ch.triangles()(hit.triangle, q));
    for (Vec3& v : vs) v += vb;  // slip relative to the moving surface
    for (const Vec3& v : vs) check_friction(body, x, v, "body feature " + std::to_string(got));
    ++checked[got];
  }
  EXPECT_GE(checked[0], 4);
  EXPECT_GE(checked[1], 2);
  EXPECT_GE(checked[2], 1);
}

}  // namespace
}  // namespace kf

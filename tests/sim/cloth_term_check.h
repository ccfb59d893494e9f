#pragma once
// The check every cloth force term (src/sim/cloth/cloth_term.h) passes, against central finite differences
// on a small sheet: its force is minus the gradient of its energy (terms that store one), its definite K
// and D are symmetric with -K and -D positive semi-definite (A stays SPD), and its adjoint shares are the
// gradients of
//     g(x, v) = hs w . f(x, v) + hs^2 w . K(x, v) c + hs w . D(x, v) dv
// (xhat's share: d g / d x; vhat's share: d g / d v - hs D^T w, zero for a term without kVelocityAdjoint)
// at fixed random w, c, dv. Each difference is taken at two step sizes and trusted only where they agree.
// The sheet is evaluated term by term here, without the fused assembly, so the check does not share the
// code it checks.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "scene/scene.h"
#include "sim/cloth/cloth_system.h"
#include "sim/cloth/cloth_term.h"

namespace kf::test {

// A sheet for term checks (cloth: a cloth block, e.g. with colliders), every particle free.
struct TermSheet {
  ClothSpec spec;
  VecX x0, mass;
  ClothSprings springs;
  std::vector<std::unique_ptr<Collider>> colliders;
  std::vector<char> free;
  // Called with the state before every evaluation: a pair collider (self contact) reads the state it
  // was updated with. Empty: nothing to update.
  std::function<void(const VecX& x, const VecX& v)> prepare;
  ClothTermSetup setup() const { return {spec, springs, colliders}; }
  int particles() const { return spec.particles(); }
};

inline std::unique_ptr<TermSheet> term_sheet(const std::string& cloth) {
  auto s = std::make_unique<TermSheet>();
  s->spec = *parse_scene(R"({"cloth": )" + cloth + "}", "term.json").cloth;
  s->spec.pins.clear();
  ClothSystem sys(s->spec, 0.01);
  VecX v;
  sys.initial_state(s->x0, v);
  s->mass = sys.masses();
  s->springs = make_cloth_springs(s->spec, s->x0);
  s->colliders = make_colliders(s->spec.colliders, s->spec.contact_ramp);
  s->free.assign(s->particles(), 1);
  return s;
}

// One term evaluated densely on the whole sheet.
template <class Term>
class TermProbe {
 public:
  explicit TermProbe(const TermSheet& sheet) : sheet_(sheet), term_(sheet.setup()) {}
  int dof() const { return 3 * sheet_.particles(); }
  const VecX& mass() const { return sheet_.mass; }

  // f (3p, N) and the definite K (N/m), D (N s/m) (3p x 3p) at (x, v) of step n.
  void eval(const VecX& x, const VecX& v, VecX& f, MatX& K, MatX& D, int n = 0) const {
    if (sheet_.prepare) sheet_.prepare(x, v);
    const ClothState s{n, x, v, sheet_.mass, sheet_.free};
    f.setZero(dof());
    K.setZero(dof(), dof());
    D.setZero(dof(), dof());
    if constexpr (Term::kStencil == ClothStencil::kParticle) {
      for (int i = 0; i < sheet_.particles(); ++i) {
        ParticleRow row;
        term_.add(s, i, /*forces=*/true, row);
        seg(f, i) += row.f;
        K.template block<3, 3>(3 * i, 3 * i) += row.K;
        D.template block<3, 3>(3 * i, 3 * i) += row.D;
      }
    } else {
      for (int k = 0; k < term_.springs(); ++k) {
        const BucklingSpring& sp = sheet_.springs.list[k];
        Vec3 fa = Vec3::Zero();
        Mat3 B = Mat3::Zero(), Bd = Mat3::Zero();
        SpringState st = measure(sp, x);
        SpringSlot slot{fa, B, Bd};
        term_.write(s, k, /*forces=*/true, st, slot);
        seg(f, sp.a) += fa;
        seg(f, sp.b) -= fa;
        scatter(K, sp, B);
        scatter(D, sp, Bd);
      }
    }
  }
  VecX force(const VecX& x, const VecX& v, int n = 0) const {
    VecX f;
    MatX K, D;
    eval(x, v, f, K, D, n);
    return f;
  }
  // The term's energy (J), 0 when it stores none.
  double energy(const VecX& x, const VecX& v, int n = 0) const {
    const ClothState s{n, x, v, sheet_.mass, sheet_.free};
    double e = 0;
    if constexpr (Term::kStencil == ClothStencil::kParticle)
      for (int i = 0; i < sheet_.particles(); ++i) term_.add_energy(s, i, e);
    else
      for (int k = 0; k < term_.springs(); ++k) e += term_.energy(x, k);
    return e;
  }
  // The term's shares of xhat and vhat (3p) in the exact adjoint: hs times its rows plus its couplings.
  void adjoint(const ClothAdjoint& a, VecX& xbar, VecX& vbar) const {
    if (sheet_.prepare) sheet_.prepare(a.x, a.v);
    xbar.setZero(dof());
    vbar.setZero(dof());
    if constexpr (Term::kStencil == ClothStencil::kParticle) {
      for (int i = 0; i < sheet_.particles(); ++i) {
        AdjointRow row;
        term_.add_adjoint(a, i, row);
        seg(xbar, i) += a.hs * row.x;
        seg(vbar, i) += a.hs * row.v;
      }
      term_.add_adjoint_coupled(a, xbar, vbar);
    } else {
      for (int k = 0; k < term_.springs(); ++k) {
        const BucklingSpring& sp = sheet_.springs.list[k];
        const SpringState st = measure(sp, a.x);
        const Vec3 dw = seg(a.w, sp.b) - seg(a.w, sp.a);
        const bool derivative = a.exact && dw.squaredNorm() > 0;
        Vec3 t = Vec3::Zero(), tv = Vec3::Zero();
        term_.spring_adjoint(a, k, st, dw, derivative, t);
        if constexpr (Term::kVelocityAdjoint) term_.spring_adjoint_v(a, k, st, dw, derivative, tv);
        seg(xbar, sp.a) += a.hs * t;
        seg(xbar, sp.b) -= a.hs * t;
        seg(vbar, sp.a) += a.hs * tv;
        seg(vbar, sp.b) -= a.hs * tv;
      }
    }
  }

 private:
  static SpringState measure(const BucklingSpring& sp, const VecX& x) {
    Vec3 f;
    Mat3 B;
    SpringState st;
    spring_force_and_definite_jacobian(sp, x, f, B, st);
    return st;
  }
  static void scatter(MatX& M, const BucklingSpring& sp, const Mat3& B) {
    M.template block<3, 3>(3 * sp.a, 3 * sp.a) -= B;
    M.template block<3, 3>(3 * sp.b, 3 * sp.b) -= B;
    M.template block<3, 3>(3 * sp.a, 3 * sp.b) += B;
    M.template block<3, 3>(3 * sp.b, 3 * sp.a) += B;
  }

  const TermSheet& sheet_;
  Term term_;
};

// Central differences of phi at z along every coordinate at step eps.
inline VecX central_gradient(const std::function<double(const VecX&)>& phi, VecX z, double eps) {
  VecX g(z.size());
  for (int k = 0; k < z.size(); ++k) {
    const double z0 = z[k];
    z[k] = z0 + eps;
    const double p = phi(z);
    z[k] = z0 - eps;
    const double m = phi(z);
    z[k] = z0;
    g[k] = (p - m) / (2 * eps);
  }
  return g;
}

// `analytic` against central differences of phi at steps eps and eps / 2, which must agree with each other
// (the differences are trusted) and with it, both to `tol` relative to the largest difference (or to
// `floor` where all are smaller). Returns the largest difference.
inline double expect_gradient(const char* what, const std::function<double(const VecX&)>& phi, const VecX& z,
                              const VecX& analytic, double eps, double tol, double floor) {
  const VecX fd1 = central_gradient(phi, z, eps), fd2 = central_gradient(phi, z, eps / 2);
  const double scale = std::max(fd2.cwiseAbs().maxCoeff(), floor);
  EXPECT_LE((fd1 - fd2).cwiseAbs().maxCoeff(), tol * scale) << what << ": the two step sizes disagree";
  EXPECT_LE((analytic - fd2).cwiseAbs().maxCoeff(), tol * scale)
      << what << ": analytic\n" << analytic.transpose() << "\nfinite differences\n" << fd2.transpose();
  return fd2.cwiseAbs().maxCoeff();
}

// What check_term measured: the largest |f|, and the largest finite differences of the energy and of g in x
// and v (so a test can assert the check did not pass on zeros).
struct TermCheck {
  double force = 0, energy_gradient = 0, adjoint_x = 0, adjoint_v = 0;
};

// The whole check at (x, v) of step n (see the header comment), w, c and dv random from `seed`, hs 0.01 s.
template <class Term>
TermCheck check_term(const TermProbe<Term>& probe, const VecX& x, const VecX& v, unsigned seed, double eps = 1e-6,
                     double tol = 1e-6, int n = 0) {
  const int dof = probe.dof();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  VecX w(dof), c(dof), dv(dof);
  for (int k = 0; k < dof; ++k) w[k] = U(rng), c[k] = U(rng), dv[k] = 0.1 * U(rng);
  const double hs = 0.01;
  TermCheck out;
  VecX f;
  MatX K, D;
  probe.eval(x, v, f, K, D, n);
  out.force = f.cwiseAbs().maxCoeff();
  // Definite blocks: symmetric, -K and -D positive semi-definite.
  const double ks = std::max(K.cwiseAbs().maxCoeff(), 1e-300), ds = std::max(D.cwiseAbs().maxCoeff(), 1e-300);
  EXPECT_LE((K - K.transpose()).cwiseAbs().maxCoeff(), 1e-12 * ks) << "K is not symmetric";
  EXPECT_LE((D - D.transpose()).cwiseAbs().maxCoeff(), 1e-12 * ds) << "D is not symmetric";
  EXPECT_LE(Eigen::SelfAdjointEigenSolver<MatX>(K).eigenvalues().maxCoeff(), 1e-10 * ks) << "-K is not PSD";
  EXPECT_LE(Eigen::SelfAdjointEigenSolver<MatX>(D).eigenvalues().maxCoeff(), 1e-10 * ds) << "-D is not PSD";
  // Energy: its gradient is -f (terms whose force has no velocity part).
  if constexpr (Term::kEnergy != nullptr)
    out.energy_gradient = expect_gradient(
        "energy gradient", [&](const VecX& y) { return probe.energy(y, v, n); }, x, -f, eps, tol, 1e-12);
  // Adjoint shares.
  auto g = [&](const VecX& y, const VecX& u) {
    VecX fy;
    MatX Ky, Dy;
    probe.eval(y, u, fy, Ky, Dy, n);
    return hs * w.dot(fy) + hs * hs * w.dot(Ky * c) + hs * w.dot(Dy * dv);
  };
  const ClothAdjoint a{n, hs, /*exact=*/true, x, v, probe.mass(), w, c, dv};
  VecX xbar, vbar;
  probe.adjoint(a, xbar, vbar);
  out.adjoint_x = expect_gradient("adjoint x share", [&](const VecX& y) { return g(y, v); }, x, xbar, eps, tol, 1e-12);
  // Its v share is measured against the part of d g / d v it leaves out (hs D^T w): a term without a
  // velocity share has none to within round-off of that.
  const double cancelled = (hs * D.transpose() * w).cwiseAbs().maxCoeff();
  out.adjoint_v = expect_gradient(
      "adjoint v share", [&](const VecX& u) { return g(x, u) - hs * w.dot(D * u); }, v, vbar, eps, tol,
      std::max(1e-12, cancelled));
  return out;
}

// A sheet state moved away from rest: positions x0 scaled by `squeeze` along the sheet's u axis (below 1:
// compressed) plus seeded noise of `jitter` metres, velocities seeded noise of `speed` m/s.
inline void perturbed_state(const TermSheet& sheet, double squeeze, double jitter, double speed, unsigned seed, VecX& x,
                            VecX& v) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> N;
  const Vec3 u = sheet.spec.u_axis.normalized(), o = sheet.spec.origin;
  x = sheet.x0;
  v.resize(x.size());
  for (int i = 0; i < sheet.particles(); ++i) {
    const Vec3 d = seg(x, i) - o;
    seg(x, i) = o + d + (squeeze - 1) * d.dot(u) * u + jitter * Vec3(N(rng), N(rng), N(rng));
    seg(v, i) = speed * Vec3(N(rng), N(rng), N(rng));
  }
}

}  // namespace kf::test

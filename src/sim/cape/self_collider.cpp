#include "sim/cape/self_collider.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace kf {

SelfCollider::SelfCollider(int particles, double thickness, double stiffness, double ramp)
    : p_(particles),
      thickness_(thickness),
      profile_{stiffness, ramp},
      x_(VecX::Zero(3 * particles)),
      v_(VecX::Zero(3 * particles)),
      cells_(particles) {}

int64_t SelfCollider::key_of(const Vec3& x, int dx, int dy, int dz) const {
  // 21 bits per axis; wrapping far away only adds candidates that the distance test rejects.
  auto c = [&](double a, int d) { return (int64_t(std::floor(a / thickness_)) + d) & 0x1FFFFF; };
  return (c(x.x(), dx) << 42) | (c(x.y(), dy) << 21) | c(x.z(), dz);
}

void SelfCollider::update(const VecX& x, const VecX& v) {
  update(x);
  v_ = v;
}

void SelfCollider::update(const VecX& x) {
  v_.setZero();
  x_ = x;
  for (int i = 0; i < p_; ++i) cells_[i] = {key_of(seg(x, i), 0, 0, 0), i};
  std::sort(cells_.begin(), cells_.end());
}

template <class Visit>
void SelfCollider::for_each_near(const Vec3& x, Visit&& visit) const {
  const double t2 = thickness_ * thickness_;
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        const int64_t key = key_of(x, dx, dy, dz);
        auto it = std::lower_bound(cells_.begin(), cells_.end(), std::make_pair(key, -1));
        for (; it != cells_.end() && it->first == key; ++it) {
          const Vec3 d = x - seg(x_, it->second);
          const double r2 = d.squaredNorm();
          if (r2 == 0.0 || r2 >= t2) continue;  // the particle itself, or out of reach
          visit(it->second, d);
        }
      }
}

Mat3 SelfCollider::pair_jacobian(const Vec3& d, bool definite) const {
  const double r = d.norm();
  const Vec3 n = d / r;
  double g, dg, ddg;
  profile_.eval(thickness_ - r, g, dg, ddg);
  Mat3 J = -dg * n * n.transpose();
  if (!definite) J += g / r * (Mat3::Identity() - n * n.transpose());
  return J;
}

bool SelfCollider::contact(int, const Vec3& x, const Vec3&, bool definite, ContactForce& out) const {
  int found = 0;
  Vec3 f = Vec3::Zero();
  Mat3 K = Mat3::Zero();
  for_each_near(x, [&](int, const Vec3& d) {
    const double r = d.norm();
    double g, dg, ddg;
    profile_.eval(thickness_ - r, g, dg, ddg);
    f += g / r * d;
    K += pair_jacobian(d, definite);
    ++found;
  });
  if (!found) return false;
  out.f = f;
  out.dfdx = K;
  out.dfdv.setZero();
  if (counting_) count_.fetch_add(found, std::memory_order_relaxed);
  return true;
}

Vec3 SelfCollider::pair_stiffness_derivative(const Vec3& d, const Vec3& w, const Vec3& c) const {
  // w . Jd c = -g'(thickness - r) (w.n)(c.n), n = d / r; dr/dd = n, dn/dd = (I - n n^T) / r.
  const double r = d.norm();
  const Vec3 n = d / r;
  double g, dg, ddg;
  profile_.eval(thickness_ - r, g, dg, ddg);
  const double wn = w.dot(n), cn = c.dot(n);
  return ddg * wn * cn * n - dg / r * (cn * (w - wn * n) + wn * (c - cn * n));
}

FrictionForce SelfCollider::pair_friction(const Vec3& d, const Vec3& u, Mat3& dfdx) const {
  // Limit L = mu g(thickness - r): dL/dd = -mu g' n; dn/dd = (I - n n^T) / r.
  const double r = d.norm();
  const Vec3 n = d / r;
  double g, dg, ddg;
  profile_.eval(thickness_ - r, g, dg, ddg);
  const FrictionForce fr = friction_force(friction_.mu * g, n, u, friction_.eps);
  dfdx = fr.dfdL * (-friction_.mu * dg * n).transpose() + fr.dfdn * (Mat3::Identity() - n * n.transpose()) / r;
  return fr;
}

void SelfCollider::pair_damping_derivative(const Vec3& d, const Vec3& u, const Vec3& a, const Vec3& b, Vec3& ddd,
                                           Vec3& ddu) const {
  const double r = d.norm();
  const Vec3 n = d / r;
  double g, dg, ddg;
  profile_.eval(thickness_ - r, g, dg, ddg);
  const FrictionDampingDerivative fd = friction_damping_derivative(friction_.mu * g, n, u, friction_.eps, a, b);
  ddd = fd.dL * (-friction_.mu * dg * n) + (fd.dn - n.dot(fd.dn) * n) / r;
  ddu = fd.du;
}

bool SelfCollider::friction(int, const Vec3& x, const Vec3& v, bool exact, ContactForce& out) const {
  if (!friction_.on()) return false;
  int found = 0;
  Vec3 f = Vec3::Zero();
  Mat3 K = Mat3::Zero(), D = Mat3::Zero(), rest = Mat3::Zero();
  for_each_near(x, [&](int j, const Vec3& d) {
    Mat3 Kf;
    const FrictionForce fr = pair_friction(d, v - seg(v_, j), Kf);
    f += fr.f;
    D += fr.damping;
    rest += fr.dfdu - fr.damping;
    K += Kf;
    ++found;
  });
  if (!found) return false;
  out.f = f;
  out.dfdv = D;
  out.dfdx = exact ? K : Mat3::Zero();
  out.dfdv_rest = exact ? rest : Mat3::Zero();
  return true;
}

void SelfCollider::add_friction_coupled(int, const VecX& w, const VecX& c, double scale, bool exact, VecX& xout,
                                        VecX& vout) const {
  if (!friction_.on()) return;
  // Pair (i, j) with d = x_i - x_j, u = v_i - v_j gives f_i = F(d, u) and f_j = F(-d, -u) = -F(d, u), so
  // d f_j / d x_i = -Kf(d, u) and d f_j / d v_i = -D(d, u) (Kf and D are even in (d, u); D is symmetric).
  // Its damping blocks D(d, u) in i's row and D(-d, -u) in j's depend on both ends: particle i gathers the
  // derivative of its own (+) and of its partners' (-). Each particle writes only itself.
  tbb::parallel_for(tbb::blocked_range<int>(0, p_, 128), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) {
      Vec3 ax = Vec3::Zero(), av = Vec3::Zero();
      for_each_near(seg(x_, i), [&](int j, const Vec3& d) {
        const Vec3 u = seg(v_, i) - seg(v_, j);
        Mat3 Kf;
        const FrictionForce fr = pair_friction(d, u, Kf);
        ax -= Kf.transpose() * seg(w, j);
        av -= fr.dfdu * seg(w, j);
        if (!exact) return;
        Vec3 dd, du;
        pair_damping_derivative(d, u, seg(w, i), seg(c, i), dd, du);
        ax += dd;
        av += du;
        pair_damping_derivative(-d, -u, seg(w, j), seg(c, j), dd, du);
        ax -= dd;
        av -= du;
      });
      seg(xout, i) += scale * ax;
      seg(vout, i) += scale * av;
    }
  });
}

void SelfCollider::add_definite_stiffness_derivative(int, const VecX&, const VecX& w, const VecX& c, double scale,
                                                     VecX& out) const {
  // Pair (i, j) puts -g' n n^T in particle i's diagonal block, a function of d = x_i - x_j; particle i
  // gathers the derivative of its own term (+) and of its partners' terms (-), so each writes only itself.
  tbb::parallel_for(tbb::blocked_range<int>(0, p_, 128), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) {
      Vec3 acc = Vec3::Zero();
      for_each_near(seg(x_, i), [&](int j, const Vec3& d) {
        acc += pair_stiffness_derivative(d, seg(w, i), seg(c, i)) - pair_stiffness_derivative(-d, seg(w, j), seg(c, j));
      });
      seg(out, i) += scale * acc;
    }
  });
}

void SelfCollider::add_cross_transpose(int, const VecX& w, double scale, VecX& out) const {
  tbb::parallel_for(tbb::blocked_range<int>(0, p_, 128), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) {
      Vec3 acc = Vec3::Zero();
      for_each_near(seg(x_, i), [&](int j, const Vec3& d) { acc -= pair_jacobian(d, false) * seg(w, j); });
      seg(out, i) += scale * acc;
    }
  });
}

}  // namespace kf

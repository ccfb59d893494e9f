#include "sim/cloth/cloth_system.h"

#include <cmath>
#include <sstream>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "sim/cloth/air_drag.h"
#include "sim/cloth/gravity.h"
#include "sim/cloth/spring_damping.h"
#include "sim/make_system.h"

namespace kf {

namespace {
// Grain sizes: below these a parallel loop costs more than it saves on two cores.
constexpr int kSpringGrain = 1024;
constexpr int kParticleGrain = 256;
}  // namespace

ClothSystem::ClothSystem(const ClothSpec& spec, double h, std::unique_ptr<PinTrack> pins,
                         std::vector<std::unique_ptr<Collider>> extra_colliders)
    : spec_(spec), p_(spec.particles()), h_(h), pins_(pins ? std::move(pins) : std::make_unique<StaticPins>()) {
  const int nx = spec.nx, ny = spec.ny;
  const double dx = spec.width / (nx - 1), dy = spec.height / (ny - 1);
  mass_.setConstant(p_, spec.mass / p_);
  x0_.resize(3 * p_);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) seg(x0_, spec.index(i, j)) = spec.origin + i * dx * spec.u_axis + j * dy * spec.v_axis;

  auto add = [&](int a, int b, double k) {
    BucklingSpring s;
    s.a = a;
    s.b = b;
    s.rest = (seg(x0_, b) - seg(x0_, a)).norm();
    s.k = k;
    s.k_post = spec.buckle_stiffness * k;
    s.f_buckle = k * s.rest * spec.buckle_strain;
    springs_.push_back(s);
  };
  // Type 1 (damped): structural, then shear.
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if (i + 1 < nx) add(spec.index(i, j), spec.index(i + 1, j), spec.stretch);
      if (j + 1 < ny) add(spec.index(i, j), spec.index(i, j + 1), spec.stretch);
    }
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      add(spec.index(i, j), spec.index(i + 1, j + 1), spec.shear);
      add(spec.index(i + 1, j), spec.index(i, j + 1), spec.shear);
    }
  damped_ = int(springs_.size());
  // Type 2: bending across two edges.
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if (i + 2 < nx) add(spec.index(i, j), spec.index(i + 2, j), spec.bend);
      if (j + 2 < ny) add(spec.index(i, j), spec.index(i, j + 2), spec.bend);
    }

  std::vector<std::vector<int>> cols(p_);
  for (int i = 0; i < p_; ++i) cols[i].push_back(i);
  for (const BucklingSpring& s : springs_) {
    cols[s.a].push_back(s.b);
    cols[s.b].push_back(s.a);
  }
  K_.set_pattern(cols);
  D_.set_pattern(cols);
  A_.set_pattern(cols);
  std::vector<std::vector<Incident>> inc(p_);
  for (int k = 0; k < int(springs_.size()); ++k) {
    const BucklingSpring& s = springs_[k];
    inc[s.a].push_back({k, +1, K_.find(s.a, s.b)});
    inc[s.b].push_back({k, -1, K_.find(s.b, s.a)});
  }
  incident_start_.assign(1, 0);
  for (auto& list : inc) {
    incident_.insert(incident_.end(), list.begin(), list.end());
    incident_start_.push_back(int(incident_.size()));
  }

  colliders_ = make_colliders(spec.colliders);
  for (auto& c : extra_colliders) colliders_.push_back(std::move(c));
  free_.assign(p_, 1);
  for (int i : spec.pins) {
    if (i < 0 || i >= p_) throw InputError("cloth: pinned particle " + std::to_string(i) + " does not exist");
    free_[i] = 0;
  }
  for (int i = 0; i < p_; ++i)
    if (!free_[i]) pinned_list_.push_back(i);

  spring_f_.assign(springs_.size(), Vec3::Zero());
  spring_K_.assign(springs_.size(), Mat3::Zero());
  spring_D_.assign(springs_.size(), Mat3::Zero());
  force_.setZero(3 * p_);
  rhs_.setZero(3 * p_);
  dv_.setZero(3 * p_);
  kv_.setZero(3 * p_);
  aw_.setZero(3 * p_);
  w_.setZero(3 * p_);
  pcg_.resize(p_, spec.cg_preconditioner == "block_jacobi" ? Preconditioner::kBlockJacobi
                                                           : Preconditioner::kIncompleteCholesky);
}

void ClothSystem::initial_state(VecX& x, VecX& v) const {
  x = x0_;
  v.resize(3 * p_);
  for (int i = 0; i < p_; ++i) seg(v, i) = spec_.velocity;
  for (int i : pinned_list_) {
    Vec3 pos, vel;
    pins_->state(0, i, seg(x0_, i), pos, vel);
    seg(x, i) = pos;
    seg(v, i) = vel;
  }
}

void ClothSystem::assemble(int n, const VecX& x, const VecX& v) {
  const int ns = int(springs_.size());
  // Each spring writes only its own slots.
  tbb::parallel_for(tbb::blocked_range<int>(0, ns, kSpringGrain), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k < r.end(); ++k) {
      const BucklingSpring& s = springs_[k];
      spring_f_[k] = spring_force(s, x);
      spring_K_[k] = spring_jacobian(s, x, /*definite=*/true);
      if (k < damped_) {
        spring_f_[k] += damping_force(s, spec_.damping, x, v);
        spring_D_[k] = damping_jacobian_v(s, spec_.damping, x);
      }
    }
  });
  // Each particle gathers its own row in a fixed order.
  const double h = h_;
  tbb::parallel_for(tbb::blocked_range<int>(0, p_, kParticleGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) {
      const double m = mass_[i];
      Vec3 f = gravity_force(m, spec_.gravity) + air_drag_force(spec_.air_drag, m, seg(v, i));
      Mat3 Kii = Mat3::Zero(), Dii = air_drag_jacobian_v(spec_.air_drag, m);
      for (int k = K_.row_start(i); k < K_.row_start(i + 1); ++k) {
        K_.block(k).setZero();
        D_.block(k).setZero();
      }
      for (int e = incident_start_[i]; e < incident_start_[i + 1]; ++e) {
        const Incident& in = incident_[e];
        f += in.sign * spring_f_[in.spring];
        K_.block(in.slot) += spring_K_[in.spring];
        Kii -= spring_K_[in.spring];
        if (in.spring < damped_) {
          D_.block(in.slot) += spring_D_[in.spring];
          Dii -= spring_D_[in.spring];
        }
      }
      ContactForce c;
      for (const auto& col : colliders_)
        if (col->contact(n, seg(x, i), seg(v, i), /*definite=*/true, c)) {
          f += c.f;
          Kii += c.dfdx;
          Dii += c.dfdv;
        }
      const int d = K_.diag_slot(i);
      K_.block(d) = Kii;
      D_.block(d) = Dii;
      seg(force_, i) = f;
      for (int k = K_.row_start(i); k < K_.row_start(i + 1); ++k)
        A_.block(k) = -h * D_.block(k) - h * h * K_.block(k);
      A_.block(d) += m * Mat3::Identity();
    }
  });
  pcg_.prepare(A_, free_);
}

bool ClothSystem::step(int n, const VecX& x, const VecX& v, const VecX& u, VecX& x_next, VecX& v_next) {
  assemble(n, x, v);
  const double h = h_;
  tbb::parallel_for(tbb::blocked_range<int>(0, p_, kParticleGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i)
      seg(rhs_, i) = h * (seg(force_, i) + h * K_.row_times(i, v) + seg(u, i));
  });
  // Pinned particles go exactly to their track position at n+1.
  for (int i : pinned_list_) {
    Vec3 pos, vel;
    pins_->state(n + 1, i, seg(x0_, i), pos, vel);
    seg(dv_, i) = (pos - seg(x, i)) / h - seg(v, i);
  }
  const bool warm = n == last_forward_n_ + 1;
  const PcgResult res = pcg_.solve(A_, free_, rhs_, dv_, spec_.cg_tolerance, spec_.cg_max_iterations, warm);
  last_forward_n_ = res.converged ? n : -2;
  last_cg_ = res.iterations;
  if (exact_springs_) {
    if (n >= int(step_dv_.size())) {
      step_dv_.resize(n + 1);
      step_x_.resize(n + 1);
    }
    step_dv_[n] = dv_;
    step_x_[n] = x;
  }
  v_next.resize(3 * p_);
  x_next.resize(3 * p_);
  v_next = v + dv_;
  x_next = x + h * v_next;
  return res.converged && x_next.allFinite() && v_next.allFinite();
}

void ClothSystem::step_adjoint(int n, const VecX& x, const VecX& v, const VecX& u, const VecX& xhat1,
                               const VecX& vhat1, VecX& xhat, VecX& vhat, VecX& uhat) {
  assemble(n, x, v);
  const double h = h_;
  rhs_ = vhat1 + h * xhat1;
  // w is zero on pinned particles.
  const bool warm = n == last_adjoint_n_ - 1;
  const PcgResult res = pcg_.solve(A_, free_, rhs_, w_, spec_.cg_tolerance, spec_.cg_max_iterations, warm);
  last_adjoint_n_ = res.converged ? n : -2;
  last_adjoint_cg_ = res.iterations;
  const VecX& w = w_;
  xhat.resize(3 * p_);
  vhat.resize(3 * p_);
  uhat.resize(3 * p_);
  // xhat needs K^T w with the exact force derivative (the definite K of A and the missing damping term
  // would bias every step by O(h), which does not vanish as h falls). Per spring G = d f_a / d x_b
  // (elastic + damping): (K^T w)_a = G^T (w_b - w_a), (K^T w)_b = -(that).
  const int ns = int(springs_.size());
  tbb::parallel_for(tbb::blocked_range<int>(0, ns, kSpringGrain), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k < r.end(); ++k) {
      const BucklingSpring& s = springs_[k];
      Mat3 G = spring_jacobian(s, x, /*definite=*/false);
      if (k < damped_) G += damping_jacobian_x(s, spec_.damping, x, v);
      spring_f_[k] = G.transpose() * (seg(w, s.b) - seg(w, s.a));
    }
  });
  tbb::parallel_for(tbb::blocked_range<int>(0, p_, kParticleGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) {
      Vec3 kw = Vec3::Zero();
      for (int e = incident_start_[i]; e < incident_start_[i + 1]; ++e)
        kw += incident_[e].sign * spring_f_[incident_[e].spring];
      ContactForce c;
      for (const auto& col : colliders_)
        if (col->contact(n, seg(x, i), seg(v, i), /*definite=*/false, c)) kw += c.dfdx.transpose() * seg(w, i);
      if (free_[i]) {
        seg(xhat, i) = seg(xhat1, i) + h * kw;
        seg(vhat, i) = mass_[i] * seg(w, i);
      } else {
        // x_pin enters the free rows through b (h K) and through the prescribed dv (A / h).
        seg(xhat, i) = h * kw + A_.row_times(i, w) / h;
        seg(vhat, i).setZero();
      }
    }
  });
  uhat = h * w;
  if (exact_springs_ && n < int(step_dv_.size()) && step_x_[n].size() == x.size() && step_x_[n] == x)
    add_dropped_spring_terms(x, v, step_dv_[n], xhat);
}

void ClothSystem::add_dropped_spring_terms(const VecX& x, const VecX& v, const VecX& dv, VecX& xhat) {
  // Per spring, with K_s, D_s its off-diagonal blocks (the diagonal ones are their negatives):
  // w^T (h^2 K c + h D dv) = -dw^T (h^2 K_s dc + h D_s ddv), dw = w_a - w_b, dc = c_a - c_b, c = v + dv.
  // K_s, D_s depend on x_b - x_a only, so the gradient in x_b is that in x_a negated.
  const double h = h_;
  const VecX& w = w_;
  xs_ = x;
  for (int k = 0; k < int(springs_.size()); ++k) {
    const BucklingSpring& s = springs_[k];
    const Vec3 dw = seg(w, s.a) - seg(w, s.b);
    if (dw.squaredNorm() == 0.0) continue;  // both ends pinned
    const Vec3 ddv = seg(dv, s.a) - seg(dv, s.b), dc = seg(v, s.a) - seg(v, s.b) + ddv;
    auto g = [&]() {
      double r = -h * h * dw.dot(spring_jacobian(s, xs_, /*definite=*/true) * dc);
      if (k < damped_) r -= h * dw.dot(damping_jacobian_v(s, spec_.damping, xs_) * ddv);
      return r;
    };
    const double e = 1e-6 * s.rest, g0 = g();
    for (int c = 0; c < 3; ++c) {
      double& xb = xs_[3 * s.b + c];
      const double x0 = xb;
      xb = x0 + e;
      const double gp = g();
      xb = x0 - e;
      const double gm = g();
      xb = x0;
      // The buckling response's stiffness jumps at the buckling load: a step across it would give the
      // jump over e. There the two one-sided differences disagree; the smaller one is the smooth side.
      const double up = (gp - g0) / e, down = (g0 - gm) / e;
      const double d = std::abs(up - down) <= 0.1 * (std::abs(up) + std::abs(down)) + 1e-12
                           ? (gp - gm) / (2 * e)
                           : (std::abs(up) < std::abs(down) ? up : down);
      xhat[3 * s.b + c] += d;
      xhat[3 * s.a + c] -= d;
    }
  }
}

void ClothSystem::save_step_context(int n, VecX& context) const {
  if (last_forward_n_ == n - 1) context = dv_;
  else context.resize(0);
}

void ClothSystem::restore_step_context(int n, const VecX& context) {
  if (context.size() == dv_.size()) {
    dv_ = context;
    last_forward_n_ = n - 1;
  } else {
    last_forward_n_ = -2;
  }
}

std::string ClothSystem::describe() const {
  std::ostringstream os;
  os << "cloth: " << spec_.nx << "x" << spec_.ny << " particles, " << springs_.size() << " springs, "
     << pinned_list_.size() << " pinned, " << colliders_.size() << " colliders, PCG ("
     << spec_.cg_preconditioner << ")";
  return os.str();
}

std::unique_ptr<System> make_cloth_system(const Scene& scene, double h) {
  return std::make_unique<ClothSystem>(*scene.cloth, h);
}

}  // namespace kf

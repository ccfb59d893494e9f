#include "sim/cloth/cloth_system.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include "core/error.h"
#include "sim/cloth/air_drag.h"
#include "sim/cloth/gravity.h"
#include "sim/cloth/imperfection.h"
#include "sim/cloth/spring_damping.h"
#include "sim/make_system.h"

namespace kf {

namespace {
// Grain sizes: below these a parallel loop costs more than it saves on two cores. Loops over particles
// use TBB's static partitioner, as the PCG's do, so each thread gets the same particles in every loop and
// their data stays in its core's cache: with TBB's default partitioner some processes ran the 50 x 50 step
// on two threads 40 % slower than others. Loops over springs do not: springs are ordered by kind, so a
// static share of them spans the whole sheet (measured slower).
constexpr int kSpringGrain = 1024;
constexpr int kParticleGrain = 256;

// "auto": IC(0) below this many particles, where its two-halves order makes it the cheapest CG
// preconditioner here on one and two threads; multigrid from there on, where IC(0)'s iteration count (which
// grows with the sheet's side while multigrid's stays flat) has caught up with it: at 100 x 100 IC(0) is
// clearly faster, at 128 x 128 the two are within a tenth of each other and multigrid wins on one thread
// (tests/results/bench/solver.csv).
constexpr int kMultigridFrom = 15000;

Preconditioner preconditioner_kind(const std::string& name, int particles) {
  if (name == "multigrid" || (name == "auto" && particles >= kMultigridFrom)) return Preconditioner::kMultigrid;
  if (name == "block_jacobi") return Preconditioner::kBlockJacobi;
  return Preconditioner::kIncompleteCholesky;
}

const char* preconditioner_name(Preconditioner p) {
  switch (p) {
    case Preconditioner::kMultigrid: return "multigrid";
    case Preconditioner::kBlockJacobi: return "block_jacobi";
    case Preconditioner::kIncompleteCholesky: break;
  }
  return "incomplete_cholesky";
}
}  // namespace

AdjointKind adjoint_kind(const std::string& name) {
  if (name == "exact") return AdjointKind::kExact;
  if (name == "swap") return AdjointKind::kSwap;
  throw std::invalid_argument("unknown adjoint \"" + name + "\" (expected exact or swap)");
}

ClothSystem::ClothSystem(const ClothSpec& spec, double h, std::unique_ptr<PinTrack> pins,
                         std::vector<std::unique_ptr<Collider>> extra_colliders)
    : spec_(spec), p_(spec.particles()), h_(h), pins_(pins ? std::move(pins) : std::make_unique<StaticPins>()) {
  const int nx = spec.nx, ny = spec.ny;
  const double dx = spec.width / (nx - 1), dy = spec.height / (ny - 1);
  mass_.setConstant(p_, spec.mass / p_);
  x0_.resize(3 * p_);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) seg(x0_, spec.index(i, j)) = spec.origin + i * dx * spec.u_axis + j * dy * spec.v_axis;
  add_imperfection(x0_, spec.u_axis.cross(spec.v_axis), spec.imperfection, uint64_t(spec.imperfection_seed));

  auto add = [&](int a, int b, double k) {
    BucklingSpring s;
    s.a = a;
    s.b = b;
    s.rest = (seg(x0_, b) - seg(x0_, a)).norm();
    s.k = k;
    s.k_post = spec.buckle_stiffness * k;
    s.f_buckle = k * s.rest * spec.buckle_strain;
    s.transverse_ramp = spec.transverse_ramp;
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
  A_.set_pattern(cols);
  std::vector<std::vector<Incident>> inc(p_);
  for (int k = 0; k < int(springs_.size()); ++k) {
    const BucklingSpring& s = springs_[k];
    inc[s.a].push_back({k, +1, A_.find(s.a, s.b)});
    inc[s.b].push_back({k, -1, A_.find(s.b, s.a)});
  }
  slot_spring_.assign(A_.nonzero_blocks(), -1);
  for (const auto& list : inc)
    for (const Incident& in : list) slot_spring_[in.slot] = in.spring;
  incident_start_.assign(1, 0);
  for (auto& list : inc) {
    incident_.insert(incident_.end(), list.begin(), list.end());
    incident_start_.push_back(int(incident_.size()));
  }

  colliders_ = make_colliders(spec.colliders, spec.contact_ramp);
  for (auto& c : extra_colliders) colliders_.push_back(std::move(c));
  free_.assign(p_, 1);
  for (int i : spec.pins) {
    if (i < 0 || i >= p_) throw InputError("cloth: pinned particle " + std::to_string(i) + " does not exist");
    free_[i] = 0;
  }
  for (int i = 0; i < p_; ++i)
    if (!free_[i]) pinned_list_.push_back(i);
  for (int k = 0; k < int(springs_.size()); ++k)
    if (!free_[springs_[k].a] || !free_[springs_[k].b]) pinned_springs_.push_back(k);

  spring_f_.assign(springs_.size(), Vec3::Zero());
  energy_parts_.assign((springs_.size() + kSpringGrain - 1) / kSpringGrain, 0.0);
  spring_K_.assign(springs_.size(), Mat3::Zero());
  spring_state_.assign(springs_.size(), SpringState());
  spring_D_.assign(springs_.size(), Mat3::Zero());
  force_.setZero(3 * p_);
  rhs_.setZero(3 * p_);
  dv_.setZero(3 * p_);
  forward_start_.resize(3 * p_);
  contact_K_.assign(p_, Mat3::Zero());
  diag_K_.assign(p_, Mat3::Zero());
  diag_D_.assign(p_, Mat3::Zero());
  aw_.setZero(3 * p_);
  w_.setZero(3 * p_);
  adjoint_start_.resize(3 * p_);
  solved_x_.setZero(3 * p_);
  solved_v_.setZero(3 * p_);
  c_.setZero(3 * p_);
  direct_solve_ = spec.direct_solver();
  split_x_.resize(spec.max_halvings);
  split_v_.resize(spec.max_halvings);
  pcg_.resize(p_, preconditioner_kind(spec.cg_preconditioner, p_), spec.nx, spec.ny);
  // IC(0) leaves out the bending springs' blocks: with the default stiffnesses they are a hundredth of the
  // stretch springs' and they reach two grid rows, so they made half the factor's blocks and a separator twice
  // as wide for a few per cent fewer iterations.
  std::vector<char> keep(A_.nonzero_blocks());
  for (int s = 0; s < A_.nonzero_blocks(); ++s) keep[s] = slot_spring_[s] < damped_;  // the diagonal is -1
  pcg_.set_factor_pattern(std::move(keep));
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

void ClothSystem::assemble(int n, const VecX& x, const VecX& v, double hs, bool forces) {
  const int ns = int(springs_.size());
  // Each spring writes only its own slots.
  tbb::parallel_for(tbb::blocked_range<int>(0, ns, kSpringGrain), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k < r.end(); ++k) {
      const BucklingSpring& s = springs_[k];
      spring_force_and_definite_jacobian(s, x, spring_f_[k], spring_K_[k], spring_state_[k]);
      if (k < damped_) {
        if (forces) spring_f_[k] += damping_force(s, spec_.damping, spring_state_[k], v);
        spring_D_[k] = damping_jacobian_v(s, spec_.damping, spring_state_[k]);
      }
    }
  });
  // Each particle gathers its own row in a fixed order.
  const double h = hs > 0 ? hs : h_;
  tbb::parallel_for(tbb::blocked_range<int>(0, p_, kParticleGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) {
      const double m = mass_[i];
      Vec3 f = gravity_force(m, spec_.gravity) + air_drag_force(spec_.air_drag, m, seg(v, i));
      Mat3 Kii = Mat3::Zero(), Dii = air_drag_jacobian_v(spec_.air_drag, m);
      // A's off-diagonal blocks are the springs' own (one spring per particle pair): K and D are never
      // stored as matrices, which keeps a 100 x 100 sheet's working set in cache.
      for (int e = incident_start_[i]; e < incident_start_[i + 1]; ++e) {
        const Incident& in = incident_[e];
        const Mat3& Ks = spring_K_[in.spring];
        if (forces) f += in.sign * spring_f_[in.spring];
        Kii -= Ks;
        if (in.spring < damped_) {
          const Mat3& Ds = spring_D_[in.spring];
          A_.block(in.slot) = -h * Ds - h * h * Ks;
          Dii -= Ds;
        } else {
          A_.block(in.slot) = -h * Mat3::Zero() - h * h * Ks;
        }
      }
      ContactForce c;
      Mat3& Kc = contact_K_[i];
      Kc.setZero();
      for (const auto& col : colliders_)
        if (col->contact(n, seg(x, i), seg(v, i), /*definite=*/true, c)) {
          f += c.f;
          Kc += c.dfdx;
          Dii += c.dfdv;
        }
      Kii += Kc;
      diag_K_[i] = Kii;
      diag_D_[i] = Dii;
      seg(force_, i) = f;
      const int d = A_.diag_slot(i);
      A_.block(d) = -h * Dii - h * h * Kii;
      A_.block(d) += m * Mat3::Identity();
    }
  }, tbb::static_partitioner());
  if (direct_solve_) direct_ok_ = direct_.factor(A_, free_);
  else pcg_.prepare(A_, free_);
}

bool ClothSystem::linear_step(int n, int depth, double t0, const VecX& x, const VecX& v, const VecX& u,
                              VecX& x_next, VecX& v_next) {
  const double h = std::ldexp(h_, -depth), t1 = t0 + std::ldexp(1.0, -depth);
  // The theta step is backward Euler's with step theta h: its solve gives w = theta (v1 - v) and
  // x1 = x + h (v + w) (see ClothSpec::theta).
  // 1 / theta is exactly 1 at theta 1, so backward Euler keeps its bits.
  const double theta = spec_.theta, hs = theta * h, inv_theta = 1 / theta;
  const bool kick = spec_.explicit_controls();  // u added after the solve, not in b
  assemble(n, x, v, hs);
  tbb::parallel_for(tbb::blocked_range<int>(0, p_, kParticleGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) {
      const Vec3 ui = kick ? Vec3::Zero() : Vec3(seg(u, i));
      seg(rhs_, i) = hs * (seg(force_, i) + hs * stiffness_times_velocity(i, v) + ui);
    }
  }, tbb::static_partitioner());
  // Substeps start cold, so a split step depends on its inputs only.
  const bool warm = depth == 0 && forward_start_.guess(n, dv_);
  // Pinned particles go exactly to their track position at n + t1 (linear within the step).
  for (int i : pinned_list_) {
    Vec3 a, b, vel;
    pins_->state(n + 1, i, seg(x0_, i), b, vel);
    if (t1 < 1) {
      pins_->state(n, i, seg(x0_, i), a, vel);
      b = (1 - t1) * a + t1 * b;
    }
    seg(dv_, i) = (b - seg(x, i)) / h - seg(v, i);
  }
  const PcgResult res = solve(rhs_, dv_, warm);
  last_cg_ += res.iterations;
  if (depth == 0) forward_start_.remember(n, dv_);
  v_next.resize(3 * p_);
  x_next.resize(3 * p_);
  // dv_ stays the solve's part: the record's dv, which the adjoint's A(x) dv terms need.
  tbb::parallel_for(tbb::blocked_range<int>(0, p_, kParticleGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) {
      const Vec3 push = kick && free_[i] ? Vec3((h / mass_[i]) * seg(u, i)) : Vec3::Zero();
      seg(v_next, i) = seg(v, i) + inv_theta * seg(dv_, i) + push;
      seg(x_next, i) = seg(x, i) + h * (seg(v, i) + seg(dv_, i) + push);  // moves with v + theta (v1 - v)
    }
  }, tbb::static_partitioner());
  return res.converged && x_next.allFinite() && v_next.allFinite();
}

// Row i of K v, with the springs' part in velocity differences: K's rows sum to the contact stiffness
// alone, so a sheet moving as a whole gives exactly no spring term instead of the round-off of large
// cancelling products (which shifted the whole sheet by thousands of ulps per step and set the noise
// floor of finite-difference checks).
Vec3 ClothSystem::stiffness_times_velocity(int i, const VecX& v) const {
  const Vec3 vi = seg(v, i);
  Vec3 kv = contact_K_[i] * vi;
  for (int k = A_.row_start(i); k < A_.row_start(i + 1); ++k)
    if (A_.col(k) != i) kv.noalias() += spring_K_[slot_spring_[k]] * (seg(v, A_.col(k)) - vi);
  return kv;
}

ClothSystem::Energy ClothSystem::energy(int n, const VecX& x, const VecX& v) const {
  return with_contact_energy(n, x, state_energy(x, v));
}

ClothSystem::Energy ClothSystem::with_contact_energy(int n, const VecX& x, Energy e) const {
  for (int i = 0; i < p_; ++i)
    for (const auto& c : colliders_) e.contact += c->energy(n, seg(x, i));
  return e;
}

ClothSystem::Energy ClothSystem::state_energy(const VecX& x, const VecX& v) const {
  Energy e;
  for (int i = 0; i < p_; ++i) {
    if (!free_[i]) continue;
    e.kinetic += 0.5 * mass_[i] * seg(v, i).squaredNorm();
    e.gravity -= mass_[i] * spec_.gravity.dot(seg(x, i));
  }
  // Springs in fixed chunks summed in chunk order: the same sum on any thread count.
  const int ns = int(springs_.size()), chunks = (ns + kSpringGrain - 1) / kSpringGrain;
  double* parts = energy_parts_.data();  // sized for every chunk at construction
  tbb::parallel_for(tbb::blocked_range<int>(0, chunks, 1), [&](const tbb::blocked_range<int>& r) {
    for (int c = r.begin(); c < r.end(); ++c) {
      double sum = 0;
      for (int k = c * kSpringGrain; k < std::min(ns, (c + 1) * kSpringGrain); ++k) sum += spring_energy(springs_[k], x);
      parts[c] = sum;
    }
  });
  for (int c = 0; c < chunks; ++c) e.elastic += parts[c];
  return e;
}

// A step's start is usually the last accepted substep's end, whose springs were just summed: reuse that
// sum (a buckled sheet's spring energies cost as much as a third of a step). Keyed by the state itself,
// so a caller that steps from anywhere else gets a fresh sum; the contact part depends on n and is
// always recomputed.
ClothSystem::Energy ClothSystem::energy_at_start(int n, const VecX& x, const VecX& v) {
  const bool cached = energy_x_.size() == x.size() && energy_x_ == x && energy_v_ == v;
  return with_contact_energy(n, x, cached ? cached_energy_ : state_energy(x, v));
}

void ClothSystem::remember_energy(const VecX& x, const VecX& v, const Energy& e) {
  energy_x_ = x;
  energy_v_ = v;
  cached_energy_ = e;
  cached_energy_.contact = 0;
}

PcgResult ClothSystem::solve(const VecX& b, VecX& x, bool warm) {
  if (!direct_solve_) return pcg_.solve(A_, free_, b, x, spec_.cg_tolerance, spec_.cg_max_iterations, warm);
  PcgResult r;
  r.converged = direct_ok_ && direct_.solve(A_, free_, b, x);
  return r;
}

double ClothSystem::external_work(const VecX& u, const VecX& x0, const VecX& x1, bool control) const {
  double w = 0;
  for (int i = 0; i < p_; ++i)
    if (control && free_[i]) w += seg(u, i).dot(seg(x1, i) - seg(x0, i));
  for (int k : pinned_springs_) {
    const BucklingSpring& s = springs_[k];
    // A pin does work -f . dx against the elastic force f on its particle (trapezoidal rule).
    const Vec3 fa = 0.5 * (spring_force(s, x0) + spring_force(s, x1));
    if (!free_[s.a]) w -= fa.dot(seg(x1, s.a) - seg(x0, s.a));
    if (!free_[s.b]) w += fa.dot(seg(x1, s.b) - seg(x0, s.b));
  }
  return w;
}

bool ClothSystem::checked_step(int n, int depth, double t0, const VecX& x, const VecX& v, const VecX& u,
                               VecX& x_next, VecX& v_next, ClothRecord& rec) {
  const bool solved = linear_step(n, depth, t0, x, v, u, x_next, v_next);
  bool accept = solved;
  if (depth < spec_.max_halvings) {
    // Backward Euler with damping never gains energy; the linearised step does when it moves particles
    // fast across springs or into colliders, and halving the step shrinks what it invents ~4-16 times.
    // An explicit control's kick is external to the solve (it may store more spring energy than its
    // work in one step): the check measures the solve's own end state.
    const bool kick = spec_.explicit_controls();
    if (kick && solved) {
      solved_v_ = v + dv_ / spec_.theta;
      solved_x_ = x + std::ldexp(h_, -depth) * (v + dv_);
    }
    const VecX& xc = kick ? solved_x_ : x_next;
    const VecX& vc = kick ? solved_v_ : v_next;
    const Energy before = energy_at_start(n, x, v), after = solved ? energy(n, xc, vc) : Energy{};
    const double work = solved ? external_work(u, x, xc, !kick) : 0.0;
    // The energy the step moves is the tolerance's scale (a NaN gain fails the test and splits).
    const double moved = before.kinetic + before.elastic + before.contact + std::abs(work) +
                         std::abs(after.gravity - before.gravity);
    accept = solved && after.total() - before.total() - work <= 1e-3 * moved + 1e-12;
    if (accept && !kick) remember_energy(x_next, v_next, after);
  }
  if (accept) {
    if (int(rec.substeps.size()) <= rec.count) rec.substeps.emplace_back();
    ClothRecord::Substep& e = rec.substeps[rec.count++];
    e.depth = depth;
    e.t0 = t0;
    e.dv = dv_;
    if (depth > 0) {  // the first substep of an unsplit step starts from the step's own state
      e.x = x;
      e.v = v;
    }
    return true;
  }
  if (depth >= spec_.max_halvings) return false;
  VecX &xm = split_x_[depth], &vm = split_v_[depth];  // sized for every depth up front: no reallocation here
  xm.resize(3 * p_);
  vm.resize(3 * p_);
  const double half = std::ldexp(1.0, -depth - 1);
  return checked_step(n, depth + 1, t0, x, v, u, xm, vm, rec) &&
         checked_step(n, depth + 1, t0 + half, xm, vm, u, x_next, v_next, rec);
}

bool ClothSystem::step(int n, const VecX& x, const VecX& v, const VecX& u, VecX& x_next, VecX& v_next,
                       StepRecord& record) {
  ClothRecord& rec = static_cast<ClothRecord&>(record);
  rec.count = 0;
  last_cg_ = 0;
  const bool ok = checked_step(n, 0, 0.0, x, v, u, x_next, v_next, rec);
  last_substeps_ = rec.count;
  if (n >= int(step_substeps_.size())) {  // grows during the first run only
    step_substeps_.resize(n + 1, 0);
    step_cg_.resize(n + 1, 0);
  }
  step_substeps_[n] = ok ? rec.count : 0;
  step_cg_[n] = last_cg_;
  // The next step starts warm only from an unsplit step's solution.
  if (!ok || rec.count != 1) forward_start_.forget();
  return ok;
}

std::vector<std::pair<std::string, double>> ClothSystem::run_stats() const {
  double steps = 0, split = 0, cg = 0;
  for (size_t n = 0; n < step_substeps_.size(); ++n) {
    if (step_substeps_[n] == 0) continue;
    ++steps;
    split += step_substeps_[n] > 1;
    cg += step_cg_[n];
  }
  std::vector<std::pair<std::string, double>> stats = {{"split_steps", split}};
  if (!direct_solve_ && steps > 0) stats.emplace_back("pcg_iterations_per_step", cg / steps);
  return stats;
}

void ClothSystem::step_adjoint(int n, const VecX& x, const VecX& v, const VecX&, const StepRecord& record,
                               const VecX& xhat1, const VecX& vhat1, VecX& xhat, VecX& vhat, VecX& uhat) {
  const ClothRecord& rec = static_cast<const ClothRecord&>(record);
  uhat.setZero(3 * p_);
  if (rec.count == 1) {
    const ClothRecord::Substep& e = rec.substeps[0];
    substep_adjoint(n, h_, x, v, e.dv, /*warm=*/true, xhat1, vhat1, xhat, vhat, uhat);
    return;
  }
  // A split step: its substeps walked back in reverse, cold, each from its own start state.
  adj_x_ = xhat1;
  adj_v_ = vhat1;
  for (int k = rec.count - 1; k >= 0; --k) {
    const ClothRecord::Substep& e = rec.substeps[k];
    const VecX& xs = k == 0 ? x : e.x;
    const VecX& vs = k == 0 ? v : e.v;
    substep_adjoint(n, std::ldexp(h_, -e.depth), xs, vs, e.dv, /*warm=*/false, adj_x_, adj_v_, xhat, vhat, uhat);
    adj_x_.swap(xhat);
    adj_v_.swap(vhat);
  }
  xhat.swap(adj_x_);
  vhat.swap(adj_v_);
  adjoint_start_.forget();
}

void ClothSystem::substep_adjoint(int n, double h, const VecX& x, const VecX& v, const VecX& dv, bool warm_ok,
                                  const VecX& xhat1, const VecX& vhat1, VecX& xhat, VecX& vhat, VecX& uhat) {
  const bool exact = adjoint_ == AdjointKind::kExact;
  // The forward solve ran with step hs = theta h and gave dv = theta (v1 - v), x1 = x + h (v + dv).
  const double theta = spec_.theta, hs = theta * h;
  assemble(n, x, v, hs, /*forces=*/false);
  rhs_ = (1 / theta) * vhat1 + h * xhat1;  // 1 / theta is exactly 1 at theta 1
  // w is zero on pinned particles (and so is every guess).
  const bool warm = warm_ok && adjoint_start_.guess(n, w_);
  const PcgResult res = solve(rhs_, w_, warm);
  if (warm_ok && res.converged) adjoint_start_.remember(n, w_);
  else adjoint_start_.forget();
  last_adjoint_cg_ = res.iterations;
  const VecX& w = w_;
  c_ = v + dv;  // v1 (without an explicit control's h u / m: what K multiplies in the step's equation)
  xhat.resize(3 * p_);
  vhat.resize(3 * p_);
  // Per spring, with dw = w_b - w_a and G = d f_a / d x_b (elastic + damping, exact): (Kx^T w)_a = G^T dw,
  // (Kx^T w)_b = -(that). The exact adjoint adds the derivative of the spring's part of
  // w^T (h K v1 + D dv) = -dw^T (h B dv1 + B_d ddv) in x_a (its negative in x_b); xhat gets h times the sum.
  const int ns = int(springs_.size());
  tbb::parallel_for(tbb::blocked_range<int>(0, ns, kSpringGrain), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k < r.end(); ++k) {
      const BucklingSpring& s = springs_[k];
      const Vec3 dw = seg(w, s.b) - seg(w, s.a);
      const bool derivative = exact && dw.squaredNorm() > 0;
      Vec3 t, dK;
      // spring_state_ is this substep's: assemble() above ran at the same positions.
      spring_adjoint_products(s, spring_state_[k], derivative, dw, seg(c_, s.b) - seg(c_, s.a), t, dK);
      if (derivative) t += hs * dK;
      if (k < damped_)
        t += damping_adjoint_products(s, spec_.damping, spring_state_[k], v, dw, derivative,
                                      seg(dv, s.b) - seg(dv, s.a));
      spring_f_[k] = t;
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
      // v1 = v + dv / theta: below 1, v1 keeps (1 - 1 / theta) of v beside what the solve gives.
      if (free_[i]) {
        seg(xhat, i) = seg(xhat1, i) + hs * kw;
        seg(vhat, i) = mass_[i] * seg(w, i);
        if (theta != 1) seg(vhat, i) += (1 - 1 / theta) * seg(vhat1, i);
      } else {
        // x_pin enters the free rows through b (hs K) and through the prescribed dv = (track - x_pin) / h
        // - v (A / h), and (exact) its own v1 = v + dv / theta.
        seg(xhat, i) = hs * kw + A_.row_times(i, w) / h;
        if (exact) seg(xhat, i) -= seg(vhat1, i) / hs;
        seg(vhat, i).setZero();
        if (exact && theta != 1) seg(vhat, i) = (1 - 1 / theta) * seg(vhat1, i);
      }
    }
  }, tbb::static_partitioner());
  for (const auto& col : colliders_) {
    col->add_cross_transpose(n, w, hs, xhat);
    if (exact) col->add_definite_stiffness_derivative(n, x, w, c_, hs * hs, xhat);
  }
  if (!spec_.explicit_controls()) {
    uhat += hs * w;
    return;
  }
  // v1 gets h u / m and x1 h^2 u / m on free particles: u's adjoint skips the solve.
  for (int i = 0; i < p_; ++i)
    if (free_[i]) seg(uhat, i) += (h / mass_[i]) * Vec3(seg(vhat1, i) + h * seg(xhat1, i));
}

BlockSparse3 ClothSystem::block_matrix(const std::vector<Mat3>& per_spring, const std::vector<Mat3>& diagonal) const {
  BlockSparse3 m = A_;
  for (int i = 0; i < p_; ++i)
    for (int k = A_.row_start(i); k < A_.row_start(i + 1); ++k) {
      const int sp = slot_spring_[k];
      m.block(k) = sp < 0 ? diagonal[i] : per_spring[sp];
    }
  return m;
}

SpMat ClothSystem::stiffness_matrix() const { return block_matrix(spring_K_, diag_K_).to_sparse(); }
SpMat ClothSystem::damping_matrix() const { return block_matrix(spring_D_, diag_D_).to_sparse(); }

void ClothSystem::save_step_context(int n, VecX& context) const { forward_start_.save(n, context); }

void ClothSystem::restore_step_context(int n, const VecX& context) { forward_start_.restore(n, context); }

std::string ClothSystem::describe() const {
  std::ostringstream os, tolerance;
  tolerance << spec_.cg_tolerance;
  os << "cloth: " << spec_.nx << "x" << spec_.ny << " particles, " << springs_.size() << " springs, "
     << pinned_list_.size() << " pinned, " << colliders_.size() << " colliders, "
     << (direct_solve_ ? std::string("sparse ") + FilteredDirect::backend() : std::string("PCG (") + preconditioner_name(preconditioner_kind(spec_.cg_preconditioner, p_)) + ", tolerance " + tolerance.str() + ")") << ", " << (adjoint_ == AdjointKind::kExact ? "exact" : "swap") << " adjoint";
  if (spec_.theta != 1) os << ", theta " << spec_.theta << " step";
  return os.str();
}

std::unique_ptr<System> make_cloth_system(const Scene& scene, double h) {
  auto sys = std::make_unique<ClothSystem>(*scene.cloth, h);
  sys->set_adjoint(adjoint_kind(scene.optimizer.adjoint));
  return sys;
}

}  // namespace kf

#include "sim/cloth/cloth_system.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include "core/error.h"
#include "sim/cape/self_collider.h"
#include "sim/cloth/imperfection.h"
#include "sim/cloth/mesh_layout.h"
#include "sim/make_system.h"

namespace kf {

namespace {
// "auto": IC(0) below this many particles, where its two-halves order makes it the cheapest CG
// preconditioner here on one and two threads; multigrid from there on, where IC(0)'s iteration count (which
// grows with the sheet's side while multigrid's stays flat) has caught up with it: at 100 x 100 IC(0) is
// clearly faster, at 128 x 128 the two are within a tenth of each other and multigrid wins on one thread
// (tests/results/bench/solver.csv).
constexpr int kMultigridFrom = 15000;

Preconditioner preconditioner_kind(CgPreconditioner chosen, int particles) {
  switch (chosen) {
    case CgPreconditioner::kMultigrid: return Preconditioner::kMultigrid;
    case CgPreconditioner::kBlockJacobi: return Preconditioner::kBlockJacobi;
    case CgPreconditioner::kIncompleteCholesky: return Preconditioner::kIncompleteCholesky;
    case CgPreconditioner::kAuto: break;
  }
  return particles >= kMultigridFrom ? Preconditioner::kMultigrid : Preconditioner::kIncompleteCholesky;
}

const char* preconditioner_name(Preconditioner p) {
  switch (p) {
    case Preconditioner::kMultigrid: return "multigrid";
    case Preconditioner::kBlockJacobi: return "block_jacobi";
    case Preconditioner::kIncompleteCholesky: break;
  }
  return "incomplete_cholesky";
}

// The grid's positions at rest (3p, metres).
VecX rest_positions(const ClothSpec& spec) {
  if (spec.mesh) return mesh_rest_positions(spec);
  const double dx = spec.width / (spec.nx - 1), dy = spec.height / (spec.ny - 1);
  VecX x0(3 * spec.particles());
  for (int j = 0; j < spec.ny; ++j)
    for (int i = 0; i < spec.nx; ++i) seg(x0, spec.index(i, j)) = spec.origin + i * dx * spec.u_axis + j * dy * spec.v_axis;
  add_imperfection(x0, spec.u_axis.cross(spec.v_axis), spec.imperfection, uint64_t(spec.imperfection_seed),
                   spec.pins);
  return x0;
}

std::vector<std::unique_ptr<Collider>> all_colliders(const ClothSpec& spec,
                                                     std::vector<std::unique_ptr<Collider>> extra) {
  std::vector<std::unique_ptr<Collider>> out = make_colliders(spec.colliders, spec.contact_ramp);
  for (auto& c : extra) out.push_back(std::move(c));
  return out;
}
}  // namespace

ClothSystem::ClothSystem(const ClothSpec& spec, double h, std::unique_ptr<PinTrack> pins,
                         std::vector<std::unique_ptr<Collider>> extra_colliders)
    : spec_(spec),
      p_(spec.particles()),
      h_(h),
      x0_(rest_positions(spec)),
      colliders_(all_colliders(spec, std::move(extra_colliders))),
      assembly_(spec, x0_, colliders_),
      pins_(pins ? std::move(pins) : std::make_unique<StaticPins>()) {
  if (spec.mesh) mass_ = mesh_masses(spec);
  else mass_.setConstant(p_, spec.mass / p_);
  free_.assign(p_, 1);
  for (int i : spec.pins) {
    if (i < 0 || i >= p_) throw InputError("cloth: pinned particle " + std::to_string(i) + " does not exist");
    free_[i] = 0;
  }
  for (int i = 0; i < p_; ++i)
    if (!free_[i]) pinned_list_.push_back(i);
  const auto& springs = assembly_.springs().list;
  for (int k = 0; k < int(springs.size()); ++k)
    if (!free_[springs[k].a] || !free_[springs[k].b]) pinned_springs_.push_back(k);
  rhs_.setZero(3 * p_);
  dv_.setZero(3 * p_);
  forward_start_.resize(3 * p_);
  w_.setZero(3 * p_);
  adjoint_start_.resize(3 * p_);
  solved_x_.setZero(3 * p_);
  solved_v_.setZero(3 * p_);
  c_.setZero(3 * p_);
  direct_solve_ = spec.direct_solver();
  split_x_.resize(spec.max_halvings);
  split_v_.resize(spec.max_halvings);
  // Multigrid is the grid's: a mesh cloth's PCG uses IC(0) (or block Jacobi) whatever the scene asks.
  if (spec.mesh) pcg_.resize(p_, spec.block_jacobi() ? Preconditioner::kBlockJacobi : Preconditioner::kIncompleteCholesky);
  else pcg_.resize(p_, preconditioner_kind(spec.cg_preconditioner, p_), spec.nx, spec.ny);
  // IC(0) leaves out the bending springs' blocks: with the default stiffnesses they are a hundredth of the
  // stretch springs' and they reach two grid rows, so they made half the factor's blocks and a separator twice
  // as wide for a few per cent fewer iterations.
  pcg_.set_factor_pattern(assembly_.factor_pattern());
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
  for (auto& c : colliders_) c->set_state(x, v);
  assembly_.assemble(ClothState{n, x, v, mass_, free_}, hs > 0 ? hs : h_, forces);
  if (direct_solve_) direct_ok_ = direct_.factor(assembly_.matrix(), free_);
  else pcg_.prepare(assembly_.matrix(), free_);
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
  tbb::parallel_for(tbb::blocked_range<int>(0, p_, kClothParticleGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) {
      const Vec3 ui = kick ? Vec3::Zero() : Vec3(seg(u, i));
      seg(rhs_, i) = hs * (seg(assembly_.force(), i) + hs * assembly_.stiffness_times_velocity(i, v) + ui);
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
  tbb::parallel_for(tbb::blocked_range<int>(0, p_, kClothParticleGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) {
      const Vec3 push = kick && free_[i] ? Vec3((h / mass_[i]) * seg(u, i)) : Vec3::Zero();
      seg(v_next, i) = seg(v, i) + inv_theta * seg(dv_, i) + push;
      seg(x_next, i) = seg(x, i) + h * (seg(v, i) + seg(dv_, i) + push);  // moves with v + theta (v1 - v)
    }
  }, tbb::static_partitioner());
  return res.converged && x_next.allFinite() && v_next.allFinite();
}

ClothSystem::Energy ClothSystem::energy(int n, const VecX& x, const VecX& v) const {
  return with_contact_energy(n, x, v, state_energy(x, v));
}

ClothSystem::Energy ClothSystem::with_contact_energy(int n, const VecX& x, const VecX& v, Energy e) const {
  assembly_.add_energy(ClothState{n, x, v, mass_, free_}, /*contact=*/true, e);
  return e;
}

ClothSystem::Energy ClothSystem::state_energy(const VecX& x, const VecX& v) const {
  Energy e;
  for (int i = 0; i < p_; ++i)
    if (free_[i]) e.kinetic += 0.5 * mass_[i] * seg(v, i).squaredNorm();
  assembly_.add_energy(ClothState{0, x, v, mass_, free_}, /*contact=*/false, e);
  return e;
}

// A step's start is usually the last accepted substep's end, whose springs were just summed: reuse that
// sum (a buckled sheet's spring energies cost as much as a third of a step). Keyed by the state itself,
// so a caller that steps from anywhere else gets a fresh sum; the contact part depends on n and is
// always recomputed.
ClothSystem::Energy ClothSystem::energy_at_start(int n, const VecX& x, const VecX& v) {
  const bool cached = energy_x_.size() == x.size() && energy_x_ == x && energy_v_ == v;
  return with_contact_energy(n, x, v, cached ? cached_energy_ : state_energy(x, v));
}

void ClothSystem::remember_energy(const VecX& x, const VecX& v, const Energy& e) {
  energy_x_ = x;
  energy_v_ = v;
  cached_energy_ = e;
  cached_energy_.contact = 0;
}

PcgResult ClothSystem::solve(const VecX& b, VecX& x, bool warm) {
  const BlockSparse3& A = assembly_.matrix();
  if (!direct_solve_) return pcg_.solve(A, free_, b, x, spec_.cg_tolerance, spec_.cg_max_iterations, warm);
  PcgResult r;
  r.converged = direct_ok_ && direct_.solve(A, free_, b, x);
  return r;
}

double ClothSystem::external_work(const VecX& u, const VecX& x0, const VecX& x1, bool control) const {
  double w = 0;
  for (int i = 0; i < p_; ++i)
    if (control && free_[i]) w += seg(u, i).dot(seg(x1, i) - seg(x0, i));
  for (int k : pinned_springs_) {
    const BucklingSpring& s = assembly_.springs().list[k];
    // A pin does work -f . dx against the elastic force f on its particle (trapezoidal rule).
    const Vec3 fa = 0.5 * (assembly_.conservative_spring_force(x0, k) + assembly_.conservative_spring_force(x1, k));
    if (!free_[s.a]) w -= fa.dot(seg(x1, s.a) - seg(x0, s.a));
    if (!free_[s.b]) w += fa.dot(seg(x1, s.b) - seg(x0, s.b));
  }
  return w;
}

void ClothSystem::accept_substep(int depth, double t0, const VecX& x, const VecX& v, ClothRecord& rec) {
  if (int(rec.substeps.size()) <= rec.count) rec.substeps.emplace_back();
  ClothRecord::Substep& e = rec.substeps[rec.count++];
  e.depth = depth;
  e.t0 = t0;
  e.dv = dv_;
  if (depth > 0) {  // the first substep of an unsplit step starts from the step's own state
    e.x = x;
    e.v = v;
  }
}

bool ClothSystem::step(int n, const VecX& x, const VecX& v, const VecX& u, VecX& x_next, VecX& v_next,
                       StepRecord& record) {
  ClothRecord& rec = static_cast<ClothRecord&>(record);
  rec.count = 0;
  last_cg_ = 0;
  const bool held = holding_ && n < int(held_.size()) && !held_[n].empty();
  cursor_ = 0;
  const bool ok = held ? held_step(n, 0, 0.0, x, v, u, x_next, v_next, rec, held_[n])
                       : checked_step(n, 0, 0.0, x, v, u, x_next, v_next, rec);
  last_substeps_ = rec.count;
  if (n >= int(step_substeps_.size())) {  // grows during the first run only
    step_substeps_.resize(n + 1, 0);
    step_cg_.resize(n + 1, 0);
  }
  if (!holding_) record_pattern(n, ok, rec);
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
  // Per spring (cloth_term.h): its share of (Kx^T w)_a, the derivative terms of the exact adjoint with it;
  // (Kx^T w)_b is its negative. xhat gets hs times each particle's sum.
  const ClothAdjoint a{n, hs, exact, x, v, mass_, w, c_, dv};
  assembly_.adjoint_springs(a);
  const BlockSparse3& A = assembly_.matrix();
  tbb::parallel_for(tbb::blocked_range<int>(0, p_, kClothParticleGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) {
      const AdjointRow row = assembly_.adjoint_row(a, i);
      const Vec3& kw = row.x;
      // v1 = v + dv / theta: below 1, v1 keeps (1 - 1 / theta) of v beside what the solve gives.
      if (free_[i]) {
        seg(xhat, i) = seg(xhat1, i) + hs * kw;
        seg(vhat, i) = mass_[i] * seg(w, i);
        if (theta != 1) seg(vhat, i) += (1 - 1 / theta) * seg(vhat1, i);
      } else {
        // x_pin enters the free rows through b (hs K) and through the prescribed dv = (track - x_pin) / h
        // - v (A / h), and (exact) its own v1 = v + dv / theta.
        seg(xhat, i) = hs * kw + A.row_times(i, w) / h;
        if (exact) seg(xhat, i) -= seg(vhat1, i) / hs;
        seg(vhat, i).setZero();
        if (exact && theta != 1) seg(vhat, i) = (1 - 1 / theta) * seg(vhat1, i);
      }
      if constexpr (ClothAssembly::kVelocityAdjoint) seg(vhat, i) += hs * row.v;
    }
  }, tbb::static_partitioner());
  assembly_.adjoint_coupled(a, xhat, vhat);
  if (!spec_.explicit_controls()) {
    uhat += hs * w;
    return;
  }
  // v1 gets h u / m and x1 h^2 u / m on free particles: u's adjoint skips the solve.
  for (int i = 0; i < p_; ++i)
    if (free_[i]) seg(uhat, i) += (h / mass_[i]) * Vec3(seg(vhat1, i) + h * seg(xhat1, i));
}

SpMat ClothSystem::stiffness_matrix() const { return assembly_.stiffness_blocks().to_sparse(); }
SpMat ClothSystem::damping_matrix() const { return assembly_.damping_blocks().to_sparse(); }

void ClothSystem::save_step_context(int n, VecX& context) const { forward_start_.save(n, context); }

void ClothSystem::restore_step_context(int n, const VecX& context) { forward_start_.restore(n, context); }

std::string ClothSystem::describe() const {
  std::ostringstream os, tolerance;
  tolerance << spec_.cg_tolerance;
  // Each collider by name, those the scene declared (by type) and those the system adds (a character's body,
  // self contact), so a count never includes colliders the scene file does not show.
  std::string names;
  for (size_t k = 0; k < colliders_.size(); ++k) {
    const char* name = k < spec_.colliders.size() ? type_name(spec_.colliders[k]) : colliders_[k]->name();
    names += (names.empty() ? "" : ", ") + std::string(name);
  }
  const size_t nc = colliders_.size();
  const std::string colliders =
      nc == 0 ? "no colliders" : std::to_string(nc) + (nc == 1 ? " collider (" : " colliders (") + names + ")";
  os << "cloth: " << (spec_.mesh ? std::to_string(p_) + " mesh" : std::to_string(spec_.nx) + "x" + std::to_string(spec_.ny)) << " particles, " << assembly_.springs().list.size() << " springs, "
     << pinned_list_.size() << " pinned, " << colliders << ", "
     << (direct_solve_ ? std::string("sparse ") + FilteredDirect::backend() : std::string("PCG (") + preconditioner_name(spec_.mesh && !spec_.block_jacobi() ? Preconditioner::kIncompleteCholesky : preconditioner_kind(spec_.cg_preconditioner, p_)) + ", tolerance " + tolerance.str() + ")") << ", " << adjoint_name(adjoint_) << " adjoint";
  if (spec_.theta != 1) os << ", theta " << spec_.theta << " step";
  return os.str();
}

std::unique_ptr<System> make_cloth_system(const Scene& scene, double h) {
  const ClothSpec& c = *scene.cloth;
  std::vector<std::unique_ptr<Collider>> extra;
  if (c.self.enabled) {  // the same term as a cape's self contact
    auto self = std::make_unique<SelfCollider>(c.particles(), c.self.thickness, c.self.stiffness,
                                               c.contact_ramp * c.self.thickness);
    self->set_friction({c.self.friction, c.self.friction_velocity});
    extra.push_back(std::move(self));
  }
  auto sys = std::make_unique<ClothSystem>(c, h, nullptr, std::move(extra));
  sys->set_adjoint(scene.optimizer.adjoint);
  return sys;
}

}  // namespace kf

#include "sim/flock/flock_system.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/check.h"
#include "sim/flock/drag_force.h"
#include "sim/flock/flock_spawn.h"
#include "sim/flock/parallel_agents.h"
#include "sim/flock/wander_force.h"
#include "sim/make_system.h"

namespace kf {

FlockSystem::FlockSystem(const FlockSpec& spec, double h, int steps, unsigned seed, double h_ref)
    : spec_(spec),
      h_(h),
      seed_(seed),
      masses_(VecX::Constant(spec.agents, spec.mass)),
      neighbor_forces_(spec) {
  if (spec.wander.strength > 0) {
    const WanderParams w{spec.wander.strength, spec.wander.correlation_steps, seed, h_ref > 0 ? h / h_ref : 1.0};
    local_forces_.push_back(std::make_unique<WanderForce>(w, spec.agents, steps));
  }
  if (spec.drag.strength > 0) local_forces_.push_back(std::make_unique<DragForce>(spec.drag.strength));
  y_.resize(dof());
  overshoot_.assign(spec.agents, 0.0);
  if (spec.implicit_damping) q_.assign(spec.agents, 0.0);
  motion_.resize(spec.agents);
  adjoint_.resize(spec.agents);
  neighbor_terms_.resize(spec.agents);
  neighbor_transposed_.resize(spec.agents);
}

std::size_t FlockSystem::record_bytes_estimate() const {
  return (sizeof(Planar) + sizeof(double)) * std::size_t(spec_.agents) * (spec_.implicit_damping ? 2 : 1);
}

void FlockSystem::initial_state(VecX& x, VecX& v) const {
  x = spawn_positions(spec_, seed_);
  v.resize(dof());
  for (int i = 0; i < spec_.agents; ++i) seg(v, i) = spec_.spawn.velocity;
}

void FlockSystem::check_size(const VecX& x, const VecX& v) const {
  CHECK_EQ(x.size(), dof());
  CHECK_EQ(v.size(), dof());
}

namespace {
// One thread's list of a slot's neighbour slots, reused by every pass: it grows with the densest
// neighbourhood met and is never freed, so a pass allocates nothing once the flock has been seen.
std::vector<int>& slot_scratch() {
  thread_local std::vector<int> slots;
  return slots;
}
// Wander and drag read neither neighbours nor x; FlockState is only their calling convention.
const NeighborLists kNoLists;
}  // namespace

void FlockSystem::index(const VecX& x, const VecX& v) {
  const int p = spec_.agents;
  if (!neighbor_forces_.any()) return;
  grid_.index(x, neighbor_forces_.radius());
  parallel_agents(p, [&](int k) {
    const int i = grid_.agent_at(k);
    motion_[k] = {x[3 * i], x[3 * i + 2], v[3 * i], v[3 * i + 2]};
  });
}

std::span<int> FlockSystem::slot_neighbors(int k) const {
  std::vector<int>& slots = slot_scratch();
  const int n = grid_.neighbors_of_slot(k, slots);
  return {slots.data(), size_t(n)};
}

void FlockSystem::size_record(FlockRecord& r) const {
  const int p = spec_.agents;
  if (int(r.b.size()) != p) {
    r.offset.resize(p);
    r.b.resize(p);
  }
  if (spec_.implicit_damping && int(r.divisor.size()) != p) {
    r.force.resize(p);
    r.divisor.resize(p);
  }
}

void FlockSystem::neighbor_pass(FlockRecord& r) {
  parallel_agents(spec_.agents, [&](int k) {
    NeighborTerms& t = neighbor_terms_[k];
    t.damping = 0;
    if (!neighbor_forces_.any()) {
      r.offset[k] = Planar{};
      r.b[k] = 1.0;
      t.force = Planar{};
      return;
    }
    t.force = neighbor_forces_.force(motion_.data(), slot_neighbors(k), k, r.offset[k], r.b[k], t.damping);
  });
}

bool FlockSystem::stable_velocity_update(int n) {
  const double worst = overshoot_.empty() ? 0.0 : *std::max_element(overshoot_.begin(), overshoot_.end());
  if (worst < 2.0) return true;
  unstable_step_ = n;
  unstable_overshoot_ = worst;
  return false;
}

std::string FlockSystem::divergence_reason() const {
  if (unstable_step_ < 0) return {};
  std::ostringstream os;
  os.precision(3);
  os << "agents packed so densely that the explicit step overshoots their velocity matching: h (matching.strength "
     << "x the summed neighbour weights + drag.strength) / mass reached " << unstable_overshoot_
     << " (it must stay below 2); set flock.step to \"implicit_damping\", raise time.substeps or lower "
     << "flock.matching.strength";
  return os.str();
}

void FlockSystem::pack_adjoint(const FlockRecord& r, const VecX& y, const std::vector<double>* q) {
  if (!neighbor_forces_.any()) return;
  const double c = neighbor_forces_.centering_strength();
  parallel_agents(spec_.agents, [&](int k) {
    const int i = grid_.agent_at(k);
    const AgentMotion& m = motion_[k];
    adjoint_[k] = {m.x,          m.z,           m.vx,          m.vz,       y[3 * i],
                   y[3 * i + 2], r.offset[k].x, r.offset[k].z, c / r.b[k], q ? (*q)[i] : 0.0};
  });
}

void FlockSystem::adjoint_weights(const FlockRecord& r, const VecX& xhat1, const VecX& vhat1) {
  const double c = spec_.matching.strength;
  // The step writes y = 0 whatever its inputs, so the y parts of xhat1 and vhat1 flow nowhere.
  parallel_agents(spec_.agents, [&](int i) {
    Vec3 si = seg(vhat1, i) + h_ * seg(xhat1, i);
    si.y() = 0;
    if (!spec_.implicit_damping) {
      seg(y_, i) = si / masses_[i];
      return;
    }
    const double m = masses_[i] * r.divisor[i];
    const Vec3 yi = si / m;
    seg(y_, i) = yi;
    q_[i] = -(yi.x() * r.force[i].x + yi.z() * r.force[i].z) * h_ * c / m;
  });
}

Vec3 FlockSystem::local_force(int n, const VecX& v, int i) const {
  const FlockState s{n, v, v, kNoLists};
  Vec3 f = Vec3::Zero();
  for (const auto& force : local_forces_) force->add_force(s, i, f);
  return f;
}

bool FlockSystem::step(int n, const VecX& x, const VecX& v, const VecX& u, VecX& x_next, VecX& v_next,
                       StepRecord& record) {
  check_size(x, v);
  FlockRecord& r = static_cast<FlockRecord&>(record);
  size_record(r);
  index(x, v);
  x_next.resize(dof());
  v_next.resize(dof());
  neighbor_pass(r);
  const double drag = std::max(spec_.drag.strength, 0.0);
  parallel_agents(spec_.agents, [&](int i) {
    const NeighborTerms& t = neighbor_terms_[slot(i)];
    Vec3 f = seg(u, i) + local_force(n, v, i);
    const double a = overshoot_[i] = h_ * (t.damping + drag) / masses_[i];
    f.x() += t.force.x;
    f.z() += t.force.z;
    Vec3 v1;
    if (spec_.implicit_damping) {
      r.force[i] = {f.x(), f.z()};
      r.divisor[i] = 1 + a;
      v1 = seg(v, i) + (h_ / (masses_[i] * (1 + a))) * f;
    } else {
      v1 = seg(v, i) + (h_ / masses_[i]) * f;
    }
    v1.y() = 0;
    Vec3 x1 = seg(x, i) + h_ * v1;
    x1.y() = 0;
    seg(v_next, i) = v1;
    seg(x_next, i) = x1;
  });
  unstable_step_ = -1;
  return x_next.allFinite() && v_next.allFinite() && (spec_.implicit_damping || stable_velocity_update(n));
}

void FlockSystem::transposed_pass(bool summed_weights) {
  parallel_agents(spec_.agents, [&](int k) {
    NeighborTransposed& t = neighbor_transposed_[k];
    if (!neighbor_forces_.any()) {
      t = NeighborTransposed{};
      return;
    }
    neighbor_forces_.transpose_apply(adjoint_.data(), slot_neighbors(k), k, t.kt, t.dt, summed_weights);
  });
}

void FlockSystem::transpose_apply(int n, const VecX& x, const VecX& v, const VecX& y, int j, Vec3& kt, Vec3& dt) const {
  const NeighborTransposed& t = neighbor_transposed_[slot(j)];
  kt = Vec3(t.kt.x, 0, t.kt.z);
  dt = Vec3(t.dt.x, 0, t.dt.z);
  // Local forces only through their interface, so a new one cannot drop out of the adjoint.
  const FlockState s{n, x, v, kNoLists};
  for (const auto& force : local_forces_) {
    force->add_KT(s, y, j, kt);
    force->add_DT(s, y, j, dt);
  }
}

void FlockSystem::step_adjoint(int n, const VecX& x, const VecX& v, const VecX&, const StepRecord& record,
                               const VecX& xhat1, const VecX& vhat1, VecX& xhat, VecX& vhat, VecX& uhat) {
  check_size(x, v);
  const FlockRecord& r = static_cast<const FlockRecord&>(record);
  const int p = spec_.agents;
  adjoint_weights(r, xhat1, vhat1);
  index(x, v);  // the step's own slots and neighbours
  pack_adjoint(r, y_, spec_.implicit_damping ? &q_ : nullptr);
  xhat.resize(dof());
  vhat.resize(dof());
  uhat.resize(dof());
  transposed_pass(spec_.implicit_damping);
  parallel_agents(p, [&](int j) {
    Vec3 kt, dt;
    transpose_apply(n, x, v, y_, j, kt, dt);
    const Vec3 yj = seg(y_, j);
    Vec3 xh = seg(xhat1, j) + h_ * kt;
    Vec3 vh = seg(vhat1, j) + h_ * seg(xhat1, j) + h_ * dt;  // s_j + h (D^T M^-1 s)_j
    Vec3 uh = h_ * yj;
    xh.y() = vh.y() = uh.y() = 0;
    seg(xhat, j) = xh;
    seg(vhat, j) = vh;
    seg(uhat, j) = uh;
  });
}

void FlockSystem::forces(int n, const VecX& x, const VecX& v, VecX& f) {
  check_size(x, v);
  size_record(scratch_);
  index(x, v);
  neighbor_pass(scratch_);
  f.resize(dof());
  parallel_agents(spec_.agents, [&](int i) {
    const NeighborTerms& t = neighbor_terms_[slot(i)];
    Vec3 fi = local_force(n, v, i);
    fi.x() += t.force.x;
    fi.z() += t.force.z;
    seg(f, i) = fi;
  });
}

void FlockSystem::apply_KT_DT(int n, const VecX& x, const VecX& v, const VecX& y, VecX& KTy, VecX& DTy) {
  check_size(x, v);
  size_record(scratch_);
  index(x, v);
  neighbor_pass(scratch_);  // centering quantities
  pack_adjoint(scratch_, y);
  transposed_pass(false);
  KTy.resize(dof());
  DTy.resize(dof());
  parallel_agents(spec_.agents, [&](int j) {
    Vec3 kt, dt;
    transpose_apply(n, x, v, y, j, kt, dt);
    seg(KTy, j) = kt;
    seg(DTy, j) = dt;
  });
}

std::string FlockSystem::describe() const {
  std::ostringstream os;
  os << "flock: " << spec_.agents << " agents, mass " << spec_.mass << " kg, forces:";
  std::vector<std::string> names;
  if (spec_.avoidance.strength > 0) names.push_back("avoidance");
  if (spec_.matching.strength > 0) names.push_back("matching");
  if (spec_.centering.strength > 0) names.push_back("centering");
  for (const auto& f : local_forces_) names.push_back(f->name());
  if (names.empty()) os << " none";
  for (size_t k = 0; k < names.size(); ++k) os << (k ? ", " : " ") << names[k];
  os << "; grid neighbour search, radius " << neighbor_forces_.radius() << " m";
  if (spec_.implicit_damping) os << "; own-velocity damping implicit";
  return os.str();
}

std::unique_ptr<System> make_flock_system(const Scene& scene, double h) {
  const double h_ref = scene.time.h();
  const int steps = int(std::ceil(scene.time.duration() / h - 1e-9));
  return std::make_unique<FlockSystem>(*scene.flock, h, steps, scene.seed, h_ref);
}

}  // namespace kf

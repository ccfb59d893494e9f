#include "sim/flock/flock_system.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "sim/flock/avoidance_force.h"
#include "sim/flock/centering_force.h"
#include "sim/flock/drag_force.h"
#include "sim/flock/flock_spawn.h"
#include "sim/flock/matching_force.h"
#include "sim/flock/parallel_agents.h"
#include "sim/flock/wander_force.h"
#include "sim/make_system.h"

namespace kf {

FlockSystem::FlockSystem(const FlockSpec& spec, double h, int steps, unsigned seed, double h_ref)
    : spec_(spec), h_(h), seed_(seed), masses_(VecX::Constant(spec.agents, spec.mass)) {
  if (spec.avoidance.strength > 0)
    forces_.push_back(std::make_unique<AvoidanceForce>(AvoidanceParams{spec.avoidance.strength, spec.avoidance.radius}));
  if (spec.matching.strength > 0)
    forces_.push_back(std::make_unique<MatchingForce>(MatchingParams{spec.matching.strength, spec.matching.radius}));
  if (spec.centering.strength > 0)
    forces_.push_back(std::make_unique<CenteringForce>(CenteringParams{spec.centering.strength, spec.centering.radius}));
  if (spec.wander.strength > 0) {
    const WanderParams w{spec.wander.strength, spec.wander.correlation_steps, seed, h_ref > 0 ? h / h_ref : 1.0};
    forces_.push_back(std::make_unique<WanderForce>(w, spec.agents, steps));
  }
  if (spec.drag.strength > 0) forces_.push_back(std::make_unique<DragForce>(spec.drag.strength));
  for (const auto& f : forces_) neighbor_radius_ = std::max(neighbor_radius_, f->radius());
  y_.resize(dof());
}

void FlockSystem::initial_state(VecX& x, VecX& v) const {
  x = spawn_positions(spec_, seed_);
  v.resize(dof());
  for (int i = 0; i < spec_.agents; ++i) seg(v, i) = spec_.spawn.velocity;
}

FlockState FlockSystem::prepare(int n, const VecX& x, const VecX& v) {
  if (x.size() != dof() || v.size() != dof())
    throw std::invalid_argument("flock state has " + std::to_string(x.size()) + " entries, expected " +
                                std::to_string(dof()));
  if (neighbor_radius_ > 0) grid_.build(x, neighbor_radius_);  // else no force reads neighbours
  FlockState s{n, x, v, grid_};
  for (auto& f : forces_) f->prepare(s);
  return s;
}

bool FlockSystem::step(int n, const VecX& x, const VecX& v, const VecX& u, VecX& x_next, VecX& v_next) {
  const FlockState s = prepare(n, x, v);
  x_next.resize(dof());
  v_next.resize(dof());
  parallel_agents(spec_.agents, [&](int i) {
    Vec3 f = seg(u, i);
    for (const auto& force : forces_) force->add_force(s, i, f);
    Vec3 v1 = seg(v, i) + (h_ / masses_[i]) * f;
    v1.y() = 0;
    Vec3 x1 = seg(x, i) + h_ * v1;
    x1.y() = 0;
    seg(v_next, i) = v1;
    seg(x_next, i) = x1;
  });
  return x_next.allFinite() && v_next.allFinite();
}

void FlockSystem::step_adjoint(int n, const VecX& x, const VecX& v, const VecX& u, const VecX& xhat1,
                               const VecX& vhat1, VecX& xhat, VecX& vhat, VecX& uhat) {
  const FlockState s = prepare(n, x, v);
  const int p = spec_.agents;
  // The step writes y = 0 whatever its inputs, so the y parts of xhat1 and vhat1 flow nowhere.
  parallel_agents(p, [&](int i) {
    Vec3 si = seg(vhat1, i) + h_ * seg(xhat1, i);
    si.y() = 0;
    seg(y_, i) = si / masses_[i];
  });
  xhat.resize(dof());
  vhat.resize(dof());
  uhat.resize(dof());
  parallel_agents(p, [&](int j) {
    Vec3 kt = Vec3::Zero(), dt = Vec3::Zero();
    for (const auto& force : forces_) {
      force->add_KT(s, y_, j, kt);
      force->add_DT(s, y_, j, dt);
    }
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
  const FlockState s = prepare(n, x, v);
  f.resize(dof());
  parallel_agents(spec_.agents, [&](int i) {
    Vec3 fi = Vec3::Zero();
    for (const auto& force : forces_) force->add_force(s, i, fi);
    seg(f, i) = fi;
  });
}

void FlockSystem::apply_KT_DT(int n, const VecX& x, const VecX& v, const VecX& y, VecX& KTy, VecX& DTy) {
  const FlockState s = prepare(n, x, v);
  KTy.resize(dof());
  DTy.resize(dof());
  parallel_agents(spec_.agents, [&](int j) {
    Vec3 kt = Vec3::Zero(), dt = Vec3::Zero();
    for (const auto& force : forces_) {
      force->add_KT(s, y, j, kt);
      force->add_DT(s, y, j, dt);
    }
    seg(KTy, j) = kt;
    seg(DTy, j) = dt;
  });
}

std::string FlockSystem::describe() const {
  std::ostringstream os;
  os << "flock: " << spec_.agents << " agents, mass " << spec_.mass << " kg, forces:";
  if (forces_.empty()) os << " none";
  for (size_t k = 0; k < forces_.size(); ++k) os << (k ? ", " : " ") << forces_[k]->name();
  os << "; grid neighbour search, radius " << neighbor_radius_ << " m";
  return os.str();
}

std::unique_ptr<System> make_flock_system(const Scene& scene, double h) {
  const double h_ref = scene.time.h();
  const int steps = int(std::ceil(scene.time.duration() / h - 1e-9));
  return std::make_unique<FlockSystem>(*scene.flock, h, steps, scene.seed, h_ref);
}

}  // namespace kf

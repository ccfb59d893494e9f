#include "sim/cape/cape_system.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <sstream>

#include "core/error.h"
#include "core/warnings.h"
#include "sim/cape/anchor_track.h"
#include "sim/cape/skin_pin_track.h"
#include "sim/character/cape_anchors.h"
#include "sim/character/scene_character.h"
#include "sim/make_system.h"

namespace kf {
namespace {

// The cloth block lays the sheet out flat; its pinned edge then jumps to the anchors in the first step.
// More than 10 cm is almost always a cloth block that does not match the character (a cape laid out a few
// centimetres off its body's back is normal).
constexpr double kPinJumpWarning = 0.10;  // m

void warn_if_pins_jump(const ClothSpec& c, const std::vector<Vec3>& anchors, const std::vector<double>& params,
                       const std::string& where) {
  const std::vector<Vec3> at_start = polyline_points(anchors, params);
  const double dx = c.nx > 1 ? c.width / (c.nx - 1) : 0.0, dy = c.ny > 1 ? c.height / (c.ny - 1) : 0.0;
  double worst = 0.0;
  size_t worst_k = 0;
  Vec3 worst_layout = Vec3::Zero();
  for (size_t k = 0; k < c.pins.size(); ++k) {
    const int i = c.pins[k] % c.nx, j = c.pins[k] / c.nx;
    const Vec3 layout = c.origin + i * dx * c.u_axis + j * dy * c.v_axis;
    const double d = (at_start[k] - layout).norm();
    if (d > worst) worst = d, worst_k = k, worst_layout = layout;
  }
  if (worst <= kPinJumpWarning) return;
  char msg[640];
  const Vec3& a = at_start[worst_k];
  std::snprintf(msg, sizeof msg,
                "%s/anchors: the cape's pinned top edge starts up to %.3f m from its anchors and jumps to them at "
                "frame 0 (particle %d: laid out at (%.3f, %.3f, %.3f) by cloth.origin, u_axis and v_axis, anchored at "
                "(%.3f, %.3f, %.3f)); lay the top edge along the anchors",
                where.c_str(), worst, c.pins[worst_k], worst_layout.x(), worst_layout.y(), worst_layout.z(), a.x(),
                a.y(), a.z());
  warn(msg);
}

// Each anchor point snaps to its nearest bind-pose vertex; farther than this is a point off the body (or
// in the wrong units) that the cape will not hang from. The shipped character's own anchors lie up to
// 12 mm from their vertices (tests/sim/character_cape_anchor_test.cpp), so the bound sits above that.
constexpr double kSnapWarning = 0.02;  // m

void warn_if_anchors_snap(const Character& character, const CapeAnchors& anchors, const std::vector<int>& ids,
                          const std::string& where) {
  const std::vector<Vec3> points = cape_anchor_points(character, anchors);
  double worst = 0;
  size_t worst_k = 0;
  for (size_t k = 0; k < ids.size(); ++k) {
    const double d = (seg(character.bind_vertices(), ids[k]) - character.placement() * points[k]).norm();
    if (d > worst) worst = d, worst_k = k;
  }
  if (worst <= kSnapWarning) return;
  char msg[512];
  std::snprintf(msg, sizeof msg,
                "%s/anchors: anchor %zu is %.3f m from the nearest vertex of the body, which the cape's edge hangs from "
                "instead (anchors snap to vertices; move the point onto the surface, or check character.scale)",
                where.c_str(), worst_k, worst);
  warn(msg);
}

// A mesh cape's length for the measures: the largest side of its rest mesh's box.
double mesh_extent(const ClothMesh& m) {
  Vec3 lo = m.vertices[0], hi = m.vertices[0];
  for (const Vec3& v : m.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  return (hi - lo).maxCoeff();
}

}  // namespace

std::unique_ptr<PinTrack> CapeSystem::anchor_track(ClothSpec& c, const CharacterSpec& character, int steps) {
  c.pins = named_pin_set("top_edge", c.nx, c.ny);
  // Top-edge particle k of nx follows the point at arc length k / (nx - 1) along the anchors' polyline.
  std::vector<double> params;
  for (int k = 0; k < int(c.pins.size()); ++k) params.push_back(c.nx > 1 ? double(k) / (c.nx - 1) : 0.5);

  // The pins' path over the whole run (one pose per step, plus one past the end for the last velocity).
  const std::vector<int> anchor_ids = cape_anchor_vertices(character_, character.anchors);
  warn_if_anchors_snap(character_, character.anchors, anchor_ids, character.where);
  std::vector<std::vector<Vec3>> anchors;
  VecX gathered;
  for (int n = 0; n <= steps + 1; ++n) {
    pose_at_frame(character_, spec_, n * h_ * fps_, pose_);
    gather_vertices(pose_, anchor_ids, gathered);
    std::vector<Vec3> a(anchor_ids.size());
    for (size_t k = 0; k < a.size(); ++k) a[k] = seg(gathered, int(k));
    anchors.push_back(std::move(a));
  }
  if (character.start_x.size() == 0) warn_if_pins_jump(c, anchors[0], params, character.where);
  return std::make_unique<AnchorTrack>(anchors, c.pins, params, c.particles(), h_);
}

CapeSystem::CapeSystem(const ClothSpec& cloth, const CharacterSpec& character, double fps, int steps, double h)
    : spec_(character), fps_(fps), h_(h), character_(load_character(character, int(std::lround(steps * h * fps)))),
      cape_length_(cloth.mesh ? mesh_extent(*cloth.mesh) : cloth.height) {
  ClothSpec c = cloth;
  // The moving body does work on the cape that a step's energy check cannot account for, so cape steps
  // are never split (its scenes use small steps).
  c.max_halvings = 0;
  std::unique_ptr<PinTrack> track;  // none: the cloth's own pins hold still (a free sheet falls onto the body)
  if (cloth.mesh) {
    // A mesh cloth's own pins follow the skin; without pins and without anchors it is free.
    if (!(cloth.pins.empty() && character.anchors.none)) track = skin_pin_track(character_, character, c, fps, steps, h);
  } else if (!character.anchors.none) {
    track = anchor_track(c, character, steps);
  }

  std::vector<std::unique_ptr<Collider>> extra;
  auto body = std::make_unique<BodyCollider>(character_.triangles(), character_.vertex_count(),
                                             spec_.body_thickness, spec_.body_stiffness, spec_.body_search,
                                             c.contact_ramp * spec_.body_thickness);
  body_ = body.get();
  body->set_friction({spec_.body_friction, spec_.body_friction_velocity});
  extra.push_back(std::move(body));
  if (spec_.self_collision) {
    auto self = std::make_unique<SelfCollider>(c.particles(), spec_.self_thickness, spec_.self_stiffness,
                                               c.contact_ramp * spec_.self_thickness);
    self_ = self.get();
    self->set_friction({spec_.self_friction, spec_.self_friction_velocity});
    extra.push_back(std::move(self));
  }
  cloth_ = std::make_unique<ClothSystem>(c, h, std::move(track), std::move(extra));
  body_count_.assign(steps + 1, 0);
  self_count_.assign(steps + 1, 0);
  min_distance_.assign(steps + 1, std::numeric_limits<double>::infinity());
}

double CapeSystem::animation_time_at(int n) const { return animation_time(spec_, n * h_ * fps_); }

VecX CapeSystem::body_at(int n) {
  VecX out;
  pose_at_frame(character_, spec_, n * h_ * fps_, out);
  return out;
}

void CapeSystem::initial_state(VecX& x, VecX& v) const {
  cloth_->initial_state(x, v);
  if (spec_.start_x.size() != x.size()) return;
  for (int i = 0; i < particles(); ++i)
    if (!cloth_->pinned(i)) {
      seg(x, i) = seg(spec_.start_x, i);
      seg(v, i) = seg(spec_.start_v, i);
    }
}

void CapeSystem::prepare(int n, const VecX& x, const VecX& v) {
  if (posed_step_ != n) {
    pose_at_frame(character_, spec_, n * h_ * fps_, pose_);
    body_->set_pose(pose_);
    if (body_->friction_params().on()) {  // friction needs the body's velocity over the step
      pose_at_frame(character_, spec_, (n + 1) * h_ * fps_, next_pose_);
      body_velocity_ = (next_pose_ - pose_) / h_;
      body_->set_velocity(body_velocity_);
    }
    posed_step_ = n;
  }
}

void CapeSystem::set_adjoint(AdjointKind kind) {
  cloth_->set_adjoint(kind);
  body_->set_curvature(kind == AdjointKind::kExact);
}

bool CapeSystem::step(int n, const VecX& x, const VecX& v, const VecX& u, VecX& x_next, VecX& v_next,
                      StepRecord& record) {
  prepare(n, x, v);
  body_->take_count();
  body_->take_min_distance();
  body_->set_counting(true);
  if (self_) {
    self_->take_count();
    self_->set_counting(true);
  }
  const bool ok = cloth_->step(n, x, v, u, x_next, v_next, record);
  body_->set_counting(false);
  const int nb = body_->take_count();
  const double phi_min = body_->take_min_distance();
  int ns = 0;
  if (self_) {
    self_->set_counting(false);
    ns = self_->take_count() / 2;
  }
  if (n >= int(body_count_.size())) {  // a run longer than the one the system was built for
    body_count_.resize(n + 1, 0);
    self_count_.resize(n + 1, 0);
    min_distance_.resize(n + 1, std::numeric_limits<double>::infinity());
  }
  body_count_[n] = nb;
  min_distance_[n] = phi_min;
  self_count_[n] = ns;
  return ok;
}

void CapeSystem::step_adjoint(int n, const VecX& x, const VecX& v, const VecX& u, const StepRecord& record,
                              const VecX& xhat1, const VecX& vhat1, VecX& xhat, VecX& vhat, VecX& uhat) {
  prepare(n, x, v);
  cloth_->step_adjoint(n, x, v, u, record, xhat1, vhat1, xhat, vhat, uhat);
}

std::string CapeSystem::describe() const {
  std::ostringstream os;
  os << "cape on " << spec_.file.filename().string() << " (" << character_.triangle_count()
     << " body triangles, self-collision " << (self_ ? "on" : "off") << "); " << cloth_->describe();
  return os.str();
}

std::vector<std::pair<std::string, double>> CapeSystem::run_stats() const {
  double body = 0, self = 0, max_body = 0, max_self = 0, contact_steps = 0;
  double min_distance = std::numeric_limits<double>::infinity();
  for (double d : min_distance_) min_distance = std::min(min_distance, d);
  for (size_t n = 0; n < body_count_.size(); ++n) {
    body += body_count_[n];
    self += self_count_[n];
    max_body = std::max(max_body, double(body_count_[n]));
    max_self = std::max(max_self, double(self_count_[n]));
    contact_steps += (body_count_[n] + self_count_[n]) > 0;
  }
  std::vector<std::pair<std::string, double>> stats = {
      {"body_contacts", body},         {"self_contacts", self},          {"max_body_contacts", max_body},
      {"max_self_contacts", max_self}, {"contact_steps", contact_steps}, {"cape_length", cape_length_}};
  // Only a distance some query measured: without one there is nothing to report.
  if (std::isfinite(min_distance)) stats.emplace_back("min_body_distance", min_distance);
  for (auto& s : cloth_->run_stats()) stats.push_back(std::move(s));
  return stats;
}

std::unique_ptr<System> make_cape_system(const Scene& scene, double h) {
  const int steps = int(std::llround(scene.time.duration() / h));
  auto sys = std::make_unique<CapeSystem>(*scene.cloth, *scene.character, scene.time.fps, steps, h);
  sys->set_adjoint(scene.optimizer.adjoint);
  return sys;
}

}  // namespace kf

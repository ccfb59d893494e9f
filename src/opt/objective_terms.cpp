#include "opt/objective_terms.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/ground_point_tree.h"
#include "core/overloaded.h"

namespace kf {

namespace {

// Particle indices a term applies to: the listed ones, or all.
std::vector<int> members(const ObjectiveSpec& s, int particles) {
  if (!s.particles.empty()) return s.particles;
  std::vector<int> all(particles);
  for (int i = 0; i < particles; ++i) all[i] = i;
  return all;
}

// ½w Σ‖x_i − t_i‖² (position) or ½w Σ‖v_i − t_i‖² (velocity).
class KeyframeTerm : public ObjectiveTerm {
 public:
  KeyframeTerm(const ObjectiveSpec& s, const std::vector<Vec3>& targets, int p, bool on_velocity)
      : frame_(s.frame), w_(s.weight), ids_(members(s, p)), targets_(targets), on_velocity_(on_velocity) {}
  std::string name() const override { return on_velocity_ ? "velocity" : "position"; }
  int frame() const override { return frame_; }
  double eval(const VecX& x, const VecX& v, VecX& gx, VecX& gv) const override {
    const VecX& q = on_velocity_ ? v : x;
    VecX& g = on_velocity_ ? gv : gx;
    long double val = 0;  // extended: round-off in φ sets the floor of a finite-difference check
    for (size_t k = 0; k < ids_.size(); ++k) {
      const Vec3 d = seg(q, ids_[k]) - targets_[targets_.size() == 1 ? 0 : k];
      val += 0.5 * w_ * d.squaredNorm();
      seg(g, ids_[k]) += w_ * d;
    }
    return double(val);
  }

 private:
  int frame_;
  double w_;
  std::vector<int> ids_;
  std::vector<Vec3> targets_;
  bool on_velocity_;
};

// ½w‖x̄ − c‖² with x̄ the mean position of the members.
class CenterOfMassTerm : public ObjectiveTerm {
 public:
  CenterOfMassTerm(const ObjectiveSpec& s, const CenterOfMassKeyframe& k, int p)
      : frame_(s.frame), w_(s.weight), ids_(members(s, p)), target_(k.target) {}
  std::string name() const override { return "center_of_mass"; }
  int frame() const override { return frame_; }
  double eval(const VecX& x, const VecX&, VecX& gx, VecX&) const override {
    Vec3 mean = Vec3::Zero();
    for (int i : ids_) mean += seg(x, i);
    mean /= double(ids_.size());
    const Vec3 d = mean - target_;
    const Vec3 g = w_ * d / double(ids_.size());
    for (int i : ids_) seg(gx, i) += g;
    return 0.5 * w_ * d.squaredNorm();
  }

 private:
  int frame_;
  double w_;
  std::vector<int> ids_;
  Vec3 target_;
};

// ½w Σ max(0, s(x_i) + m)² over agents, s the signed distance to the boundary of a ground region S given
// as a polygon in (x, z), holes left out (negative inside), m the margin: agents are pulled to at least m inside. With
// m = 0 this is ½w Σ dist(x_i, S)² over agents outside. The gradient w (s + m) ∇s is continuous across the
// boundary (∇s is the unit direction away from the closest boundary point, outward).
// Agents into a polygon on the ground: ½w Σ s_i² with s_i the distance outside the region (plus a margin
// inside the boundary when margin > 0). With coverage, the region filled too: ½w_c Σ_j (2r max(0, √D_j − r))²
// over the region samples q_j, with D_j a soft minimum of the squared distances ‖q_j − x_i‖² (log-sum-exp
// at temperature (r/4)², smooth where the nearest agent changes). Measured in distance, like the inside
// term, a sample's penalty grows with the square of its gap, so the two keep their balance when a shape and
// its crowd are scaled up together (samples and agents both grow with the area); the factor 2r makes it
// (D_j − r²)² to first order where a gap closes (D_j → r²), so a weight keeps its meaning there.
class ShapeTerm : public ObjectiveTerm {
 public:
  ShapeTerm(const ObjectiveSpec& s, const ShapeKeyframe& k, int p)
      : frame_(s.frame), w_(s.weight), margin_(k.margin), ids_(members(s, p)), region_(k.polygon, k.holes),
        wc_(k.coverage_weight), r_(k.coverage_radius), r2_(r_ * r_), tau_(r2_ / 16),
        samples_(k.coverage_weight > 0 ? region_samples(region_, k.coverage_spacing) : std::vector<Vec2>{}) {}
  std::string name() const override { return "shape"; }
  int frame() const override { return frame_; }
  double eval(const VecX& x, const VecX&, VecX& gx, VecX&) const override {
    long double val = 0;  // extended: round-off in φ sets the floor of a finite-difference check
    for (int i : ids_) {
      const Vec2 q(x[3 * i], x[3 * i + 2]);
      bool inside = false;
      const Vec2 c = closest_point_in_polygon(region_, q, &inside);
      Vec2 g;
      if (!inside) {
        g = q - c;  // (s + m) ∇s with s = |q - c|, m = 0; below for m > 0
        if (margin_ > 0) {
          const double s = g.norm();
          if (s == 0) continue;
          g *= (s + margin_) / s;
        }
      } else {
        if (margin_ <= 0) continue;
        const Vec2 away = closest_point_on_boundary(region_, q) - q;  // inward distance, pointing out
        const double depth = away.norm();
        if (depth >= margin_ || depth == 0) continue;
        g = (margin_ - depth) / depth * away;
      }
      val += 0.5 * w_ * g.squaredNorm();
      gx[3 * i] += w_ * g.x();
      gx[3 * i + 2] += w_ * g.y();
    }
    if (!samples_.empty()) {
      for (int i : ids_)  // a position that is not finite has no nearest agent; the rollout counts as diverged
        if (!std::isfinite(x[3 * i]) || !std::isfinite(x[3 * i + 2])) return std::numeric_limits<double>::quiet_NaN();
      tree_.build(x, ids_);
      for (const Vec2& q : samples_) val += coverage(q, x, gx);
    }
    return double(val);
  }

 private:
  // One region sample's coverage penalty; adds its gradient. Linear in the members: the soft minimum
  // Σ exp(-(d²_i − nearest)/τ) reads only the members within (d² − nearest)/τ ≤ kSoftCut of q, found in tree_.
  // A member left out weighs under e^-50 ≈ 2e-22 of the nearest's 1, so even 100,000 of them move the sum by
  // less than its round-off: φ and the gradient are those of summing over every member.
  double coverage(const Vec2& q, const VecX& x, VecX& gx) const {
    const double nearest = tree_.nearest_squared(q, r2_);  // stops at the first member within r
    if (nearest - r2_ <= 0) return 0;  // D ≤ nearest: an agent is within r, no penalty
    tree_.within(q, nearest + kSoftCut * tau_, near_);  // in member order, the order of summing over all
    double sum = 0;
    for (const auto& f : near_) sum += std::exp(-(f.squared - nearest) / tau_);
    const double soft = nearest - tau_ * std::log(sum);
    if (soft - r2_ <= 0) return 0;
    const double root = std::sqrt(soft), gap = root - r_;  // metres beyond r
    const double dphi_dsoft = 4 * wc_ * r2_ * gap / (2 * root);
    for (const auto& f : near_) {
      const int i = ids_[f.index];
      const double dsoft = std::exp(-(f.squared - nearest) / tau_) / sum;  // ∂D/∂d²_i
      const double c = dphi_dsoft * dsoft * 2;
      gx[3 * i] += c * (x[3 * i] - q.x());
      gx[3 * i + 2] += c * (x[3 * i + 2] - q.y());
    }
    return 2 * wc_ * r2_ * gap * gap;
  }

  static constexpr double kSoftCut = 50;
  int frame_;
  double w_, margin_;
  std::vector<int> ids_;
  GroundRegion region_;  // before samples_, which are read from it
  double wc_, r_, r2_, tau_;
  std::vector<Vec2> samples_;
  // The members' (x, z) at the evaluated frame and one sample's nearby members: rebuilt by each evaluation,
  // reused by every sample (evaluations are sequential).
  mutable GroundPointTree tree_;
  mutable std::vector<GroundPointTree::Found> near_;
};

// ½w Σ (‖r⊥_i‖ − R)², r⊥ the offset of x_i from the cylinder axis: cloth onto an arch.
class ArchTerm : public ObjectiveTerm {
 public:
  ArchTerm(const ObjectiveSpec& s, const ArchKeyframe& k, int p)
      : frame_(s.frame), w_(s.weight), ids_(members(s, p)), a_(k.axis_point), e_(k.axis), r_(k.radius) {}
  std::string name() const override { return "arch"; }
  int frame() const override { return frame_; }
  double eval(const VecX& x, const VecX&, VecX& gx, VecX&) const override {
    long double val = 0;  // extended: round-off in φ sets the floor of a finite-difference check
    for (int i : ids_) {
      const Vec3 d = seg(x, i) - a_;
      const Vec3 perp = d - d.dot(e_) * e_;
      const double len = perp.norm();
      if (len < 1e-12) continue;  // on the axis the distance is not differentiable; no pull
      const double err = len - r_;
      val += 0.5 * w_ * err * err;
      seg(gx, i) += w_ * err * perp / len;
    }
    return double(val);
  }

 private:
  int frame_;
  double w_;
  std::vector<int> ids_;
  Vec3 a_, e_;
  double r_;
};

}  // namespace

std::unique_ptr<ObjectiveTerm> make_objective_term(const ObjectiveSpec& s, int particles) {
  using Term = std::unique_ptr<ObjectiveTerm>;
  return std::visit(
      Overloaded{
          [&](const PositionKeyframe& k) -> Term { return std::make_unique<KeyframeTerm>(s, k.targets, particles, false); },
          [&](const VelocityKeyframe& k) -> Term { return std::make_unique<KeyframeTerm>(s, k.targets, particles, true); },
          [&](const CenterOfMassKeyframe& k) -> Term { return std::make_unique<CenterOfMassTerm>(s, k, particles); },
          [&](const ShapeKeyframe& k) -> Term { return std::make_unique<ShapeTerm>(s, k, particles); },
          [&](const ArchKeyframe& k) -> Term { return std::make_unique<ArchTerm>(s, k, particles); },
      },
      s.kind);
}

}  // namespace kf

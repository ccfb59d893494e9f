// shape (flocks): agents into a polygon on the ground and, with coverage, filling it. Measured by
// inside_fraction, coverage_fraction (of the region's sample points with an agent within coverage_radius),
// coverage_radius, coverage_spacing, min_spacing and median_spacing (nearest-neighbour distances, metres).
// Tolerance: inside_fraction >= 0.95 and, when coverage is asked, coverage_fraction >= 0.9.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/ground_point_tree.h"
#include "core/ground_region.h"
#include "opt/keyframes/ground_spacing.h"
#include "opt/keyframes/keyframe_common.h"
#include "opt/keyframes/keyframe_rules.h"

namespace kf {

namespace {

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
      : frame_(s.frame), w_(s.weight), margin_(k.margin), ids_(keyframe_members(s, p)), region_(k.polygon, k.holes),
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

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace

template <>
struct KeyframeRules<ShapeKeyframe> {
  static std::unique_ptr<ObjectiveTerm> term(const ObjectiveSpec& s, const ShapeKeyframe& k, int particles) {
    return std::make_unique<ShapeTerm>(s, k, particles);
  }

  static KeyframeMeasure measure(const KeyframeRun& run, const ObjectiveSpec&, const ShapeKeyframe& k) {
    const VecX& x = run.t.x[run.f];
    const GroundRegion region(k.polygon, k.holes);
    int inside = 0;
    const int p = int(x.size() / 3);
    for (int i = 0; i < p; ++i) inside += polygon_contains(region, Vec2(x[3 * i], x[3 * i + 2]));
    const auto nn = nearest_neighbour_spacing(x);
    const double inside_fraction = double(inside) / p;
    KeyframeMeasure m;
    m.from_target = false;  // judged by the fractions it reached
    m.report["inside_fraction"] = inside_fraction;
    m.report["min_spacing"] = *std::min_element(nn.begin(), nn.end());
    m.report["median_spacing"] = median(nn);
    // Filled, not clumped: the fraction of the region's sample points with an agent within the radius.
    // A crowd's shape may need more samples at its spacing than a region may have: measured more coarsely, so
    // the report does not fail after the optimisation it reports.
    const double spacing = sample_spacing_within_limit(region, k.coverage_spacing);
    const std::vector<Vec2> samples = region_samples(region, spacing);
    const std::vector<char> near = points_covered(x, samples, k.coverage_radius);
    const int covered = int(std::count(near.begin(), near.end(), char(1)));
    const double coverage_fraction = samples.empty() ? 1.0 : double(covered) / double(samples.size());
    m.report["coverage_fraction"] = coverage_fraction;
    m.report["coverage_radius"] = k.coverage_radius;
    m.report["coverage_spacing"] = spacing;
    const bool coverage = k.coverage_weight > 0;
    const double in = (1 - inside_fraction) / (1 - 0.95);
    m.judged = true;
    m.miss = coverage ? std::max(in, (1 - coverage_fraction) / (1 - 0.9)) : in;
    m.error = coverage ? format_number("inside %.3f coverage %.3f", inside_fraction, coverage_fraction)
                       : format_number("inside %.3f", inside_fraction);
    m.tolerance = coverage ? "inside >= 0.95 and coverage >= 0.9" : "inside >= 0.95";
    return m;
  }

  static KeyframePlacement placement(const ObjectiveSpec&, const ShapeKeyframe&) { return {}; }
};

template struct KeyframeKind<ShapeKeyframe>;

}  // namespace kf

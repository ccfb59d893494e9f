// position: ½w Σ‖x_i − t_i‖² over the listed particles (all when none are listed). Measured by the RMS
// distance from the targets (cloth: also over the sheet's width); on one agent of a flock it is a race, the
// agent from last to first along the flock's heading. Tolerance: cloth 1 cm or 1 % of the sheet; a racer
// first along the heading; other flock positions 0.1 m.
#include <algorithm>
#include <cmath>
#include <limits>

#include "opt/keyframes/keyframe_common.h"
#include "opt/keyframes/keyframe_rules.h"

namespace kf {

namespace {

// Groups of the flock at one frame: agents linked when closer than `radius` (union-find).
int flock_groups(const VecX& x, double radius) {
  const int p = int(x.size() / 3);
  std::vector<int> up(static_cast<size_t>(p));
  for (int i = 0; i < p; ++i) up[size_t(i)] = i;
  auto root = [&](int i) {
    while (up[size_t(i)] != i) i = up[size_t(i)] = up[size_t(up[size_t(i)])];
    return i;
  };
  int groups = p;
  for (int i = 0; i < p; ++i)
    for (int j = i + 1; j < p; ++j)
      if ((seg(x, i) - seg(x, j)).squaredNorm() <= radius * radius) {
        const int a = root(i), b = root(j);
        if (a != b) up[size_t(a)] = b, --groups;
      }
  return groups;
}

// The race: rank_at_start, rank_at_end along the heading (0 = last, agents-1 = first), last_at_start,
// first_at_end, racer_rank (1 = first), racer_lead, racer_within_front, flock_groups_max, flock_connected.
void race_measures(const Scene& scene, const ObjectiveSpec& o, const PositionKeyframe& k, const Trajectory& t, int f,
                   nlohmann::json& m) {
  const VecX& x = t.x[f];
  const int a = o.particles[0];
  Vec3 heading = mean_of(t.x[f], {}) - mean_of(t.x[0], {});
  if (heading.norm() < 1e-12) heading = Vec3::UnitX();
  heading.normalize();
  auto rank = [&](const VecX& s) {
    const double mine = seg(s, a).dot(heading);
    int r = 0;
    for (int i = 0; i < s.size() / 3; ++i) r += (i != a && seg(s, i).dot(heading) < mine);
    return r;
  };
  const int p = int(x.size() / 3);
  const int r0 = rank(t.x[0]), r1 = rank(x);
  m["rank_at_start"] = r0;
  m["rank_at_end"] = r1;
  m["last_at_start"] = r0 == 0;
  m["first_at_end"] = r1 == p - 1;
  m["racer_rank"] = p - r1;  // 1: the front of the flock along its heading
  // How far ahead of the next agent: the racer should lead the flock, not leave it.
  double next = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < p; ++i)
    if (i != a) next = std::max(next, seg(x, i).dot(heading));
  const double radius = scene.flock->centering.radius;
  m["racer_lead"] = seg(x, a).dot(heading) - next;
  m["racer_within_front"] = m["racer_lead"].get<double>() <= radius;
  // One group throughout: links up to the centering radius connect every agent at every frame up to f.
  int most = 0;
  for (int g = 0; g <= f; ++g) most = std::max(most, flock_groups(t.x[size_t(g)], radius));
  m["flock_groups_max"] = most;
  m["flock_connected"] = most == 1;
  m["rms_error"] = (seg(x, a) - k.targets[0]).norm();
}

}  // namespace

template <>
struct KeyframeRules<PositionKeyframe> {
  static std::unique_ptr<ObjectiveTerm> term(const ObjectiveSpec& s, const PositionKeyframe& k, int particles) {
    return std::make_unique<TargetsTerm>(s, k.targets, particles, false);
  }

  static KeyframeMeasure measure(const KeyframeRun& run, const ObjectiveSpec& o, const PositionKeyframe& k) {
    KeyframeMeasure m;
    m.error_phrase = " from its targets (RMS)";
    if (run.scene.flock && o.particles.size() == 1) {  // a race: the agent first along the heading
      race_measures(run.scene, o, k, run.t, run.f, m.report);
      m.judged = true;
      m.miss = m.report["racer_rank"].get<double>();
      m.error = format_number("rank %.0f", m.miss);
      m.tolerance = "rank 1";
      return m;
    }
    int n = 0;
    const double sum = target_squared_error(o, k.targets, run.t.x[run.f], n);
    const double rms = std::sqrt(sum / n);
    m.report["rms_error"] = rms;
    if (!run.scene.cloth) {
      judge_distance(m, rms, 0.1);
      return m;
    }
    const double width = sheet_width(run.scene, run.t.x[0]);
    m.report["rms_over_width"] = width > 0 ? rms / width : 0.0;
    judge_distance(m, rms, cloth_tolerance(run.scene));
    return m;
  }

  static KeyframePlacement placement(const ObjectiveSpec&, const PositionKeyframe& k) {
    return {KeyframePlacement::Kind::kParticles, k.targets};
  }
};

template struct KeyframeKind<PositionKeyframe>;

}  // namespace kf

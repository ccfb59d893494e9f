#include "report/figure_measures.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/check.h"
#include "core/overloaded.h"
#include "opt/objective_terms.h"
#include "sim/cloth/collider.h"
#include "sim/flock/neighbor_grid.h"

namespace kf {

std::vector<double> nearest_neighbour_spacing(const VecX& x) {
  // Linear in the agents: each agent's nearest among those a grid finds within twice the mean spacing over
  // the flock's box; only agents with none that close are compared with all. Exact either way (the nearest
  // lies among the agents within any radius that holds one), and hypot does not see the sign of its inputs,
  // so every value is the one comparing all pairs gives.
  const int p = int(x.size() / 3);
  std::vector<double> nn(p, std::numeric_limits<double>::infinity());
  if (p < 2) return nn;
  double x0 = x[0], x1 = x[0], z0 = x[2], z1 = x[2];
  for (int i = 1; i < p; ++i) {
    x0 = std::min(x0, x[3 * i]), x1 = std::max(x1, x[3 * i]);
    z0 = std::min(z0, x[3 * i + 2]), z1 = std::max(z1, x[3 * i + 2]);
  }
  double radius = 2.0 * std::sqrt((x1 - x0) * (z1 - z0) / p);
  if (!(radius > 1e-9 && radius < 1e9)) radius = 1.0;  // coincident, collinear or non-finite positions
  auto distance = [&](int i, int j) { return std::hypot(x[3 * i] - x[3 * j], x[3 * i + 2] - x[3 * j + 2]); };
  NeighborGrid grid;
  grid.build(x, radius);
  for (int i = 0; i < p; ++i)
    for (int j : grid.neighbors(i)) nn[i] = std::min(nn[i], distance(i, j));
  for (int i = 0; i < p; ++i)
    if (grid.neighbors(i).empty())
      for (int j = 0; j < p; ++j)
        if (j != i) nn[i] = std::min(nn[i], distance(i, j));
  return nn;
}

std::vector<char> points_covered(const VecX& x, const std::vector<Vec2>& q, double radius) {
  // The points join the particles for one grid search a little wider than the radius; each pair found is
  // then tested exactly.
  const int p = int(x.size() / 3), s = int(q.size());
  std::vector<char> covered(s, 0);
  if (p == 0 || s == 0 || !(radius > 0)) return covered;
  VecX all = VecX::Zero(3 * (std::size_t(p) + s));
  all.head(3 * p) = x;
  for (int k = 0; k < s; ++k) all[3 * (p + k)] = q[k].x(), all[3 * (p + k) + 2] = q[k].y();
  NeighborGrid grid;
  grid.build(all, radius * (1 + 1e-9) + 1e-12);
  for (int k = 0; k < s; ++k)
    for (int i : grid.neighbors(p + k))
      if (i < p && Vec2(x[3 * i] - q[k].x(), x[3 * i + 2] - q[k].y()).squaredNorm() <= radius * radius) {
        covered[k] = 1;
        break;
      }
  return covered;
}

namespace {

Vec3 mean_of(const VecX& x, const std::vector<int>& ids) {
  Vec3 m = Vec3::Zero();
  if (ids.empty()) {
    for (int i = 0; i < x.size() / 3; ++i) m += seg(x, i);
    return m / double(x.size() / 3);
  }
  for (int i : ids) m += seg(x, i);
  return m / double(ids.size());
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace

namespace {

// Each keyframe type's measures at its frame f (x = t.x[f]), added to m.
void shape_measures(const ShapeKeyframe& k, const VecX& x, nlohmann::json& m) {
  const GroundRegion region(k.polygon, k.holes);
  int inside = 0;
  const int p = int(x.size() / 3);
  for (int i = 0; i < p; ++i) inside += polygon_contains(region, Vec2(x[3 * i], x[3 * i + 2]));
  const auto nn = nearest_neighbour_spacing(x);
  m["inside_fraction"] = double(inside) / p;
  m["min_spacing"] = *std::min_element(nn.begin(), nn.end());
  m["median_spacing"] = median(nn);
  // Filled, not clumped: the fraction of the region's sample points with an agent within the radius.
  // A crowd's shape may need more samples at its spacing than a region may have: measured more coarsely, so
  // the report does not fail after the optimisation it reports.
  const double spacing = sample_spacing_within_limit(region, k.coverage_spacing);
  const std::vector<Vec2> samples = region_samples(region, spacing);
  const std::vector<char> near = points_covered(x, samples, k.coverage_radius);
  const int covered = int(std::count(near.begin(), near.end(), char(1)));
  m["coverage_fraction"] = samples.empty() ? 1.0 : double(covered) / double(samples.size());
  m["coverage_radius"] = k.coverage_radius;
  m["coverage_spacing"] = spacing;
}

void center_of_mass_measures(const Scene& scene, const ObjectiveSpec& o, const CenterOfMassKeyframe& k,
                             const Trajectory& t, const VecX& x, nlohmann::json& m) {
  // Path: the start's centre of mass, then every centre-of-mass target in frame order.
  std::vector<std::pair<int, Vec3>> pts{{0, mean_of(t.x[0], o.particles)}};
  for (const auto& q : scene.objectives)
    if (const auto* c = std::get_if<CenterOfMassKeyframe>(&q.kind)) pts.emplace_back(q.frame, c->target);
  std::stable_sort(pts.begin(), pts.end(), [](auto& a, auto& b) { return a.first < b.first; });
  double length = 0;
  for (size_t j = 1; j < pts.size(); ++j) length += (pts[j].second - pts[j - 1].second).norm();
  const double err = (mean_of(x, o.particles) - k.target).norm();
  m["error"] = err;
  m["path_length"] = length;
  m["error_over_path"] = length > 0 ? err / length : 0.0;
}

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

// The race: one agent of a flock from last to first along the flock's heading, the flock one group.
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

// Sum of squared distances of the objective's particles in q (positions or velocities) to their targets.
double target_squared_error(const ObjectiveSpec& o, const std::vector<Vec3>& targets, const VecX& q, int& n) {
  double sum = 0;
  n = o.particles.empty() ? int(q.size() / 3) : int(o.particles.size());
  for (int j = 0; j < n; ++j) {
    const int i = o.particles.empty() ? j : o.particles[j];
    sum += (seg(q, i) - targets[targets.size() == 1 ? 0 : j]).squaredNorm();
  }
  return sum;
}

// The sheet's width at frame 0 (x0): a grid's first row's length; a mesh's largest extent along an axis.
double sheet_width(const Scene& scene, const VecX& x0) {
  if (!scene.cloth || !scene.cloth->mesh) {
    const int nx = scene.cloth ? scene.cloth->nx : 1;
    return (seg(x0, nx - 1) - seg(x0, 0)).norm();
  }
  const Eigen::Map<const Eigen::Matrix<double, 3, Eigen::Dynamic>> p(x0.data(), 3, x0.size() / 3);
  return (p.rowwise().maxCoeff() - p.rowwise().minCoeff()).maxCoeff();
}

void position_measures(const Scene& scene, const ObjectiveSpec& o, const PositionKeyframe& k, const Trajectory& t,
                       int f, nlohmann::json& m) {
  if (scene.flock && o.particles.size() == 1) return race_measures(scene, o, k, t, f, m);
  int n = 0;
  const double sum = target_squared_error(o, k.targets, t.x[f], n);
  m["rms_error"] = std::sqrt(sum / n);
  if (scene.cloth) {
    const double width = sheet_width(scene, t.x[0]);
    m["rms_over_width"] = width > 0 ? std::sqrt(sum / n) / width : 0.0;
  }
}

void arch_measures(const Scene& scene, const ArchKeyframe& k, const Trajectory& t, const VecX& x, nlohmann::json& m) {
  double sum = 0;
  const int p = int(x.size() / 3);
  for (int i = 0; i < p; ++i) {
    const Vec3 d = seg(x, i) - k.axis_point;
    const double e = (d - d.dot(k.axis) * k.axis).norm() - k.radius;
    sum += e * e;
  }
  const double width = sheet_width(scene, t.x[0]);
  m["rms_distance"] = std::sqrt(sum / p);
  m["width"] = width;
  m["rms_over_width"] = width > 0 ? std::sqrt(sum / p) / width : 0.0;
}

// How far a free sheet turned over: the angle of its normal (from the corner diagonals) from frame 0's.
nlohmann::json sheet_measures(const ClothSpec& cloth, const Trajectory& t) {
  const int a = 0, b = cloth.nx - 1, c = (cloth.ny - 1) * cloth.nx, d = cloth.nx * cloth.ny - 1;
  auto normal = [&](const VecX& x) {
    const Vec3 n = (seg(x, d) - seg(x, a)).cross(seg(x, c) - seg(x, b));
    return n.norm() > 0 ? Vec3(n.normalized()) : Vec3::UnitY();
  };
  const Vec3 n0 = normal(t.x[0]);
  auto degrees = [&](const VecX& x) { return std::acos(std::clamp(n0.dot(normal(x)), -1.0, 1.0)) * 180.0 / M_PI; };
  double most = 0;
  for (int f = 0; f < t.frames(); ++f) most = std::max(most, degrees(t.x[size_t(f)]));
  return {{"type", "sheet"}, {"flip_degrees", most}, {"flip_degrees_at_end", degrees(t.x.back())}};
}

}  // namespace

namespace {

// A collider's own measures over a run (null for shapes that have none): a ring's crossing, a free sheet's
// landing on the ground.
nlohmann::json collider_measures(const ClothSpec& cloth, const ColliderSpec& c, const Trajectory& t) {
  return std::visit(Overloaded{
                        [&](const TorusShape& torus) { return ring_measures(torus, t); },
                        [&](const GroundShape& ground) {
                          return cloth.pins.empty() ? ground_measures(ground, c.thickness, t) : nlohmann::json();
                        },
                        [](const SphereShape&) { return nlohmann::json(); },
                        [](const CapsuleShape&) { return nlohmann::json(); },
                        [&](const BoxShape&) { return surface_measures(c, t); },
                        [&](const RectangleShape&) { return surface_measures(c, t); },
                    },
                    c.shape);
}

}  // namespace

nlohmann::json figure_measures(const Scene& scene, const Trajectory& t) {
  nlohmann::json out = nlohmann::json::array();
  CHECK_GT(t.frames(), 0);
  CHECK_EQ(t.particles, scene.particles());
  const int last = t.frames() - 1;
  for (const auto& o : scene.objectives) {
    const int f = std::min(o.frame, last);
    const VecX& x = t.x[f];
    nlohmann::json m = {{"type", type_name(o)}, {"frame", o.frame}};
    std::visit(Overloaded{
                   [&](const PositionKeyframe& k) { position_measures(scene, o, k, t, f, m); },
                   [&](const VelocityKeyframe& k) {
                     int n = 0;
                     m["rms_error"] = std::sqrt(target_squared_error(o, k.targets, t.v[f], n) / n);
                   },
                   [&](const CenterOfMassKeyframe& k) { center_of_mass_measures(scene, o, k, t, x, m); },
                   [&](const ShapeKeyframe& k) { shape_measures(k, x, m); },
                   [&](const ArchKeyframe& k) { arch_measures(scene, k, t, x, m); },
               },
               o.kind);
    out.push_back(m);
  }
  // Then the system's own measures.
  visit_system(scene, Overloaded{
                          [](const FlockSpec&) {},
                          [&](const ClothSpec& cloth) {
                            if (cloth.pins.empty() && !cloth.mesh) out.push_back(sheet_measures(cloth, t));
                            for (size_t k = 0; k < cloth.colliders.size(); ++k) {
                              nlohmann::json m = collider_measures(cloth, cloth.colliders[k], t);
                              if (m.is_null()) continue;
                              m["collider"] = int(k);
                              out.push_back(m);
                            }
                          },
                      });
  return out;
}

nlohmann::json cape_end_state(const Scene& scene, const Trajectory& run, const Trajectory& uncontrolled) {
  if (!scene.character || !scene.cloth || scene.character->target_run.empty()) return nlohmann::json();
  // The end target: the position and velocity keyframes the character block appended.
  const ObjectiveSpec *pos = nullptr, *vel = nullptr;
  for (const auto& o : scene.objectives) {
    if (o.source != ObjectiveSource::kEndTarget) continue;
    if (std::holds_alternative<PositionKeyframe>(o.kind)) pos = &o;
    if (std::holds_alternative<VelocityKeyframe>(o.kind)) vel = &o;
  }
  if (!pos || !vel) return nlohmann::json();
  const auto& pos_targets = std::get<PositionKeyframe>(pos->kind).targets;
  const auto& vel_targets = std::get<VelocityKeyframe>(vel->kind).targets;
  const double length = scene.cloth->height;
  auto rms = [](const VecX& q, const std::vector<Vec3>& t) {
    double sum = 0;
    for (size_t i = 0; i < t.size(); ++i) sum += (seg(q, int(i)) - t[i]).squaredNorm();
    return std::sqrt(sum / double(t.size()));
  };
  auto of = [&](const Trajectory& t) {
    const int f = std::min(pos->frame, t.frames() - 1);
    const double ex = rms(t.x[f], pos_targets);
    return nlohmann::json{{"rms_position_error", ex},
                          {"rms_position_error_percent", 100.0 * ex / length},
                          {"rms_velocity_error", rms(t.v[std::min(vel->frame, t.frames() - 1)], vel_targets)}};
  };
  return {{"frame", pos->frame}, {"cape_length", length}, {"controlled", of(run)}, {"uncontrolled", of(uncontrolled)}};
}

nlohmann::json ground_measures(const GroundShape& ground, double thickness, const Trajectory& t) {
  const Vec3 n = ground.normal.normalized();
  const VecX& x = t.x.back();
  double lowest = std::numeric_limits<double>::infinity(), sum = 0;
  const int p = int(x.size() / 3);
  for (int i = 0; i < p; ++i) {
    const double h = n.dot(seg(x, i) - ground.point);
    lowest = std::min(lowest, h);
    sum += h;
  }
  // Resting on it: within two contact thicknesses (the contact springs hold a sheet about one above it).
  return {{"type", "ground"},
          {"lowest_at_end", lowest},
          {"mean_height_at_end", sum / std::max(1, p)},
          {"on_ground_at_end", lowest <= 2 * thickness}};
}

nlohmann::json surface_measures(const ColliderSpec& collider, const Trajectory& t) {
  const std::vector<std::unique_ptr<Collider>> made = make_colliders({collider}, 0.0);
  const auto& surface = dynamic_cast<const DistanceCollider&>(*made.front());
  double min_phi = std::numeric_limits<double>::infinity();
  int min_frame = 0, touching = 0;
  for (int f = 0; f < t.frames(); ++f) {
    const VecX& x = t.x[size_t(f)];
    for (int i = 0; i < x.size() / 3; ++i) {
      double phi;
      Vec3 n;
      Mat3 dn;
      surface.distance(seg(x, i), phi, n, dn);
      if (phi < min_phi) {
        min_phi = phi;
        min_frame = f;
      }
      if (f + 1 == t.frames() && phi <= 2 * collider.thickness) ++touching;
    }
  }
  return {{"type", type_name(collider)},
          {"min_distance", min_phi},
          {"min_distance_frame", min_frame},
          {"touching_at_end", touching}};
}

namespace {

// The smallest signed distance to the ring along each particle's straight path from one frame to the next
// (at most `so_far`). The simulation's contacts act only at steps, so a fast particle could pass through
// the tube unseen by the frames. Paths whose whole length is farther from the surface than their half length
// cannot come closer than that; the others are sampled at `spacing` (m).
double min_distance_between_frames(const TorusCollider& ring, const Trajectory& t, double spacing, double so_far) {
  double min_between = so_far;
  for (int f = 0; f + 1 < t.frames(); ++f)
    for (int i = 0; i < t.x[size_t(f)].size() / 3; ++i) {
      const Vec3 a = seg(t.x[size_t(f)], i), b = seg(t.x[size_t(f) + 1], i);
      double phi;
      Vec3 n;
      Mat3 dn;
      ring.distance(0.5 * (a + b), phi, n, dn);
      const double half = 0.5 * (b - a).norm();
      if (phi - half >= min_between) continue;  // cannot lower the minimum
      const int samples = 1 + int(std::ceil(2 * half / spacing));
      for (int k = 0; k <= samples; ++k) {
        ring.distance(a + (b - a) * (double(k) / samples), phi, n, dn);
        min_between = std::min(min_between, phi);
      }
    }
  return min_between;
}

}  // namespace

nlohmann::json ring_measures(const TorusShape& torus, const Trajectory& t) {
  const TorusCollider ring(torus, 0.0, 0.0, 0.0);  // distances only
  const Vec3 axis = torus.axis.normalized();
  const double inner = torus.radius - torus.tube_radius;
  double min_phi = std::numeric_limits<double>::infinity();
  double min_axis = std::numeric_limits<double>::infinity();
  int crossings = 0;
  Vec3 prev = Vec3::Zero();
  for (int f = 0; f < t.frames(); ++f) {
    const VecX& x = t.x[f];
    for (int i = 0; i < x.size() / 3; ++i) {
      double phi;
      Vec3 n;
      Mat3 dn;
      ring.distance(seg(x, i), phi, n, dn);
      min_phi = std::min(min_phi, phi);
    }
    const Vec3 com = mean_of(x, {});
    if (f > 0) {
      const double a0 = axis.dot(prev - torus.center), a1 = axis.dot(com - torus.center);
      if ((a0 < 0) != (a1 < 0)) {
        // Where the straight segment between the two frames' centres of mass meets the ring's plane.
        const double s = a0 / (a0 - a1);
        const Vec3 d = prev + s * (com - prev) - torus.center;
        min_axis = std::min(min_axis, (d - axis.dot(d) * axis).norm());
        ++crossings;
      }
    }
    prev = com;
  }
  const double min_between = min_distance_between_frames(ring, t, 0.25 * torus.tube_radius, min_phi);
  // Where the sheet ends, along the ring's axis from its plane, in the direction it crossed (positive: beyond).
  const Vec3 end_com = mean_of(t.x.back(), {});
  const double start_side = axis.dot(mean_of(t.x.front(), {}) - torus.center);
  nlohmann::json m = {{"type", "ring"}};
  m["crossings"] = crossings;
  m["inner_radius"] = inner;
  m["through_ring"] = crossings > 0 && min_axis < inner;
  m["min_distance_to_ring_axis_when_crossing"] = crossings > 0 ? nlohmann::json(min_axis) : nlohmann::json();
  m["min_signed_distance"] = min_phi;
  m["min_signed_distance_between_frames"] = min_between;
  m["penetration_free"] = min_phi >= 0 && min_between >= 0;
  m["end_beyond_ring_plane"] = (start_side < 0 ? 1.0 : -1.0) * axis.dot(end_com - torus.center);
  return m;
}

}  // namespace kf

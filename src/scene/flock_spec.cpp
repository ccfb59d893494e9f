#include "scene/flock_spec.h"

#include <cmath>
#include <sstream>

#include "scene/params.h"

namespace kf {

namespace {

FlockSpec::NeighbourForce parse_neighbour_force(Block b, FlockSpec::NeighbourForce def) {
  FlockSpec::NeighbourForce f;
  f.strength = b.number("strength", def.strength, 0.0, 1e6);
  f.radius = b.number("radius", def.radius, 1e-3, 1e4);
  b.finish();
  return f;
}

// Flocks live on the ground plane: a y component other than 0 is a mistake in the scene.
Vec3 planar_vec3(Block& b, const std::string& key, const Vec3& def, double lo, double hi) {
  Vec3 v = b.vec3(key, def, lo, hi);
  if (v.y() != 0) {
    std::ostringstream os;
    os << "expected [x, 0, z] (flocks live on the ground plane y = 0), got y = " << v.y();
    b.fail(key, os.str());
  }
  return v;
}

}  // namespace

int lattice_points_in_disc(double spacing, double radius, int cap) {
  if (radius < 0) return 0;
  const double rr = (radius / spacing) * (radius / spacing);
  long count = 0;
  // Rows outward from the centre so a large disc stops as soon as it holds `cap` points.
  for (long a = 0; double(a * a) <= rr && count < cap; ++a) {
    const long half = long(std::floor(std::sqrt(rr - double(a * a))));
    count += (a == 0 ? 1 : 2) * (2 * half + 1);
  }
  return int(std::min<long>(count, cap));
}

FlockSpec parse_flock_spec(Block& b) {
  FlockSpec s;
  s.agents = b.integer("agents", s.agents, 1, 1'000'000);
  s.mass = b.number("mass", s.mass, 1e-6, 1e6);
  s.implicit_damping = b.string("step", "explicit", {"explicit", "implicit_damping"}) == "implicit_damping";
  // Forces first: the spawn check needs the avoidance radius.
  s.avoidance = parse_neighbour_force(b.child("avoidance"), s.avoidance);
  s.matching = parse_neighbour_force(b.child("matching"), s.matching);
  s.centering = parse_neighbour_force(b.child("centering"), s.centering);
  {
    Block w = b.child("wander");
    s.wander.strength = w.number("strength", s.wander.strength, 0.0, 1e6);
    s.wander.correlation_steps = w.integer("correlation_steps", s.wander.correlation_steps, 1, 1'000'000);
    w.finish();
  }
  {
    Block d = b.child("drag");
    s.drag.strength = d.number("strength", s.drag.strength, 0.0, 1e6);
    d.finish();
  }
  {
    Block sp = b.child("spawn");
    s.spawn.center = planar_vec3(sp, "center", s.spawn.center, -1e6, 1e6);
    s.spawn.radius = sp.number("radius", s.spawn.radius, 0.0, 1e6);
    s.spawn.velocity = planar_vec3(sp, "velocity", s.spawn.velocity, -1e4, 1e4);
    const double dmin = s.min_spawn_distance();
    if (s.agents > 1 && lattice_points_in_disc(dmin, s.spawn.radius, s.agents) < s.agents) {
      // Smallest radius that holds the agents at the minimum spacing (an estimate from the disc area).
      double need = dmin * std::sqrt(s.agents / M_PI);
      while (lattice_points_in_disc(dmin, need, s.agents) < s.agents) need *= 1.02;
      std::ostringstream os;
      os << "too small for " << s.agents << " agents at least " << dmin
         << " m apart (0.6 x avoidance radius); need at least " << std::ceil(need * 100) / 100 << ", got "
         << s.spawn.radius;
      sp.fail("radius", os.str());
    }
    sp.finish();
  }
  b.finish();
  return s;
}

}  // namespace kf

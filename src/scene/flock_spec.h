#pragma once
// A flock of agents on the ground plane (y = 0) as the scene file states it.
//
// Every force has a strength (0 switches it off) and, for neighbour forces, a radius beyond which it
// is exactly zero. Units: metres, seconds, kilograms, newtons.
#include "core/types.h"

namespace kf {
class Block;

struct FlockSpec {
  int agents = 200;
  double mass = 1.0;  // kg per agent

  struct Spawn {
    Vec3 center = Vec3::Zero();    // [x, 0, z], m
    double radius = 8.0;           // disc the agents start in, m (200 agents ~1 m apart)
    Vec3 velocity = Vec3::Zero();  // [vx, 0, vz], m/s, the same for every agent
  } spawn;

  // Neighbour forces: strength in N (avoidance), N/(m/s) (matching), N/m (centering); radius in m.
  struct NeighbourForce {
    double strength;
    double radius;
  };
  NeighbourForce avoidance{6.0, 1.5};
  NeighbourForce matching{0.5, 3.0};
  NeighbourForce centering{1.0, 5.0};

  struct Wander {
    double strength = 0.5;      // N, per horizontal component at most
    int correlation_steps = 30;  // steps between independent random values (smoothly interpolated)
  } wander;

  struct Drag {
    double strength = 0.2;  // N/(m/s)
  } drag;

  // How a step takes an agent's own-velocity damping (matching's pull toward its neighbours' velocities and
  // drag): explicitly, as paper eq. 1 does (the default), or at the end of the step, which no packing can
  // make overshoot (FlockSystem explains both).
  bool implicit_damping = false;

  // Agents never start closer than this (m): 0.6 x the avoidance radius.
  double min_spawn_distance() const { return 0.6 * avoidance.radius; }
};

// Reads the "flock" block (and its sub-blocks); throws InputError naming the JSON pointer of a bad key.
FlockSpec parse_flock_spec(Block& b);

// Number of points of a square lattice with spacing `spacing` (m, centred on the origin) inside a disc of
// radius `radius` (m), counted up to `cap`. Spawning places agents on such a lattice, so this is what a
// disc can hold.
int lattice_points_in_disc(double spacing, double radius, int cap);

}  // namespace kf

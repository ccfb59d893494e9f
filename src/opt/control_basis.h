#pragma once
// The basis of a block of controls (ControlBasis, scene/control_kind.h): how one block of variables gives
// a value per particle (an initial velocity, or one step's force), the transpose of that (the chain rule
// back), and the block that comes closest to given per-particle values. One struct per basis; Controls
// (controls.h) holds one and decides the timing. Only the controlled components (x, z on the ground; x, y,
// z otherwise) are read or written.
#include <array>
#include <utility>
#include <variant>
#include <vector>

#include "core/types.h"
#include "scene/control_kind.h"

namespace kf {

// One variable per particle and controlled component.
struct ParticleBasis {
  ParticleBasis(int particles, std::vector<int> comps) : particles(particles), comps(std::move(comps)) {}
  int size() const { return particles * int(comps.size()); }
  void spread(const double* block, VecX& per_particle) const;       // adds the block's values
  void collect(const VecX& per_particle, double* block) const;      // adds the transpose
  void fit(const VecX& per_particle, double* block) const;          // the values themselves
  int particles;
  std::vector<int> comps;
};

// A 3 x 3 lattice over the initial sheet's two widest principal axes: particle i gets Σ_k w_ik z_k, bilinear
// over its cell's four nodes.
struct LatticeBasis {
  static constexpr int kSide = 3, kNodes = kSide * kSide;
  LatticeBasis(int particles, std::vector<int> comps, const VecX& x0);
  int size() const { return kNodes * int(comps.size()); }
  void spread(const double* block, VecX& per_particle) const;
  void collect(const VecX& per_particle, double* block) const;
  void fit(const VecX& per_particle, double* block) const;  // least squares
  int particles;
  std::vector<int> comps;
  std::vector<std::array<std::pair<int, double>, 4>> weights;  // each particle's four (node, weight)
};

// The whole body's rigid motion z = (Δv, ω): particle i gets Δv + ω × (x0_i − c).
struct RigidBasis {
  RigidBasis(int particles, std::vector<int> comps, const VecX& x0);
  int size() const { return 6; }
  void spread(const double* block, VecX& per_particle) const;
  void collect(const VecX& per_particle, double* block) const;
  void fit(const VecX& per_particle, double* block) const;  // not defined: throws std::logic_error
  int particles;
  std::vector<int> comps;
  VecX arms;  // x0_i − c
};

using AnyControlBasis = std::variant<ParticleBasis, LatticeBasis, RigidBasis>;

// The basis `b` for `particles` particles at rest positions x0 (3p), controlling components `comps`.
AnyControlBasis make_control_basis(ControlBasis b, int particles, std::vector<int> comps, const VecX& x0);

}  // namespace kf

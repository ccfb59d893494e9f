#pragma once
// Cloth self-collision: particle pairs closer than `thickness` repel with g(thickness - r) along the line
// between them (ContactProfile g), found through a spatial hash rebuilt per state.
//
// It fits the per-particle Collider interface as a gather: the contact of particle i sums its pairs and
// gives d f_i / d x_i. The cross blocks d f_i / d x_j (= -d f_i / d x_i of that pair) cannot go through
// that interface; the cloth's implicit matrix A leaves them out (like a block-Jacobi stiffness), and
// add_cross_transpose puts them into the adjoints' Kx^T w so xhat uses the exact Jacobian.
//
// Friction (Collider::set_friction) acts on each pair against the relative velocity u = v_i - v_j, with limit
// mu g(thickness - r) and normal n = d / r. Its velocity coupling is the same gather: the damping block
// (friction.h) in the implicit matrix, the rest of d f_i / d v_i in the exact Jacobian, and the cross block
// d f_i / d v_j = -d f_i / d v_i through add_friction_coupled.
#include <atomic>
#include <cstdint>
#include <utility>
#include <vector>

#include "sim/cloth/collider.h"

namespace kf {

class SelfCollider final : public Collider {
 public:
  const char* name() const override { return "self contact"; }
  // particles: p; thickness, ramp: metres; stiffness: N/m.
  SelfCollider(int particles, double thickness, double stiffness, double ramp);

  // Positions (3p, metres) and velocities (3p, m/s; friction reads them) of the state the next contact()
  // calls see. Allocation-free. Without velocities every particle counts as still.
  void update(const VecX& x);
  void update(const VecX& x, const VecX& v);
  void set_state(const VecX& x, const VecX& v) override { update(x, v); }

  // Sums the pairs of the particle at x (it must be one of the updated positions; the particle itself is
  // recognised by its identical position). df/dx: per pair -g' n n^T, plus g/r (I - n n^T) unless
  // `definite`.
  bool contact(int n, const Vec3& x, const Vec3& v, bool definite, ContactForce& out) const override;
  // Pairs need both ends: the whole-cloth form below carries the derivative, so this one is zero.
  Vec3 definite_stiffness_derivative(int, const Vec3&, const Vec3&, const Vec3&) const override { return Vec3::Zero(); }
  // Over the pairs of the updated state (x is not read); parallel per particle, each writing only itself.
  void add_definite_stiffness_derivative(int n, const VecX& x, const VecX& w, const VecX& c, double scale,
                                         VecX& out) const override;
  // out_i += scale * sum_j (d f_j / d x_i)^T w_j = -scale * sum_j J_ij w_j over the pairs of the updated
  // state (w, out: 3p). Parallel per particle i, each writing only its own entries.
  void add_cross_transpose(int n, const VecX& w, double scale, VecX& out) const override;
  // Friction: the particle's pairs summed (slip u = v - v_j, v_j from update); the cross blocks and the
  // damping blocks' derivatives over the pairs of the updated state in add_friction_coupled (parallel per
  // particle, each writing only its own entries).
  bool friction(int n, const Vec3& x, const Vec3& v, bool exact, ContactForce& out) const override;
  void add_friction_coupled(int n, const VecX& w, const VecX& c, double scale, bool exact, VecX& xout,
                            VecX& vout) const override;

  // Pair Jacobian J = d f_i / d x_i of one pair with offset d = x_i - x_j (|d| < thickness).
  Mat3 pair_jacobian(const Vec3& d, bool definite) const;
  // d/dd [w . Jd c] of one pair, Jd = pair_jacobian(d, definite = true).
  Vec3 pair_stiffness_derivative(const Vec3& d, const Vec3& w, const Vec3& c) const;
  // Friction of one pair on particle i (offset d, slip u = v_i - v_j) and its exact d f_i / d x_i.
  FrictionForce pair_friction(const Vec3& d, const Vec3& u, Mat3& dfdx) const;
  // d/dd and d/du of [a . D(d, u) b], D = pair_friction(d, u).damping (the block the implicit matrix holds).
  void pair_damping_derivative(const Vec3& d, const Vec3& u, const Vec3& a, const Vec3& b, Vec3& ddd,
                               Vec3& ddu) const;

  void set_counting(bool on) { counting_ = on; }
  // Particle contacts counted since the last take (each pair counts twice).
  int take_count() { return count_.exchange(0); }

 private:
  int64_t key_of(const Vec3& x, int dx, int dy, int dz) const;
  template <class Visit>
  void for_each_near(const Vec3& x, Visit&& visit) const;

  int p_;
  double thickness_;
  ContactProfile profile_;
  VecX x_, v_;
  std::vector<std::pair<int64_t, int>> cells_;  // (cell key, particle), sorted
  bool counting_ = false;
  mutable std::atomic<int> count_{0};
};

}  // namespace kf

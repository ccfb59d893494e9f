#pragma once
// The one loop that sums the cloth's terms (cloth_terms.h) into a step: the force f, the blocks of the
// definite K and D and of A = M - h D - h^2 K, the state's energy, and the exact adjoint's products.
//
// Fused and cache-friendly: K and D are never stored as matrices. Spring terms write their spring's own
// slot (parallel over springs); then each particle gathers its row in a fixed order (particle terms and
// its springs' slots, in list order) and writes its own blocks of A (parallel over particles, each
// thread always the same particles). Nothing is summed across threads, so results are bit-identical on
// any thread count; nothing is allocated after construction.
#include <memory>
#include <vector>

#include "sim/cloth/block_sparse.h"
#include "sim/cloth/cloth_terms.h"

namespace kf {

// Grain sizes: below these a parallel loop costs more than it saves on two cores. Loops over particles
// use TBB's static partitioner, as the PCG's do, so each thread gets the same particles in every loop and
// their data stays in its core's cache: with TBB's default partitioner some processes ran the 50 x 50 step
// on two threads markedly slower than others. Loops over springs do not: springs are ordered by kind, so a
// static share of them spans the whole sheet (measured slower).
inline constexpr int kClothSpringGrain = 1024;
inline constexpr int kClothParticleGrain = 256;

namespace cloth_terms {
template <class Tuple>
struct Traits;
template <class... Ts>
struct Traits<std::tuple<Ts...>> {
  static constexpr bool kVelocityAdjoint = (Ts::kVelocityAdjoint || ...);
  // The index of the first spring term (where a row gathers its springs' slots), and the number of them.
  static constexpr int first_spring() {
    int i = 0, first = -1;
    ((first < 0 && Ts::kStencil == ClothStencil::kSpring ? first = i : 0, ++i), ...);
    return first;
  }
  static constexpr int spring_terms = ((Ts::kStencil == ClothStencil::kSpring ? 1 : 0) + ...);
  static constexpr bool springs_together() {
    int i = 0, last = -1;
    ((Ts::kStencil == ClothStencil::kSpring ? last = i : 0, ++i), ...);
    return first_spring() < 0 || last - first_spring() + 1 == spring_terms;
  }
  static constexpr bool spring_velocity_adjoint =
      ((Ts::kStencil == ClothStencil::kSpring && Ts::kVelocityAdjoint) || ...);
};
using ListTraits = Traits<ClothTerms>;
static_assert(ListTraits::first_spring() >= 0, "the cloth needs its springs");
static_assert(ListTraits::springs_together(), "the spring terms of ClothTerms must be next to each other");
}  // namespace cloth_terms

class ClothAssembly {
 public:
  // x0: the rest state's positions (3p, metres; the springs' rest lengths). The colliders are the
  // system's, alive as long as this.
  ClothAssembly(const ClothSpec& spec, const VecX& x0, const std::vector<std::unique_ptr<Collider>>& colliders);
  ClothAssembly(const ClothAssembly&) = delete;
  ClothAssembly& operator=(const ClothAssembly&) = delete;

  // True when a term's K or D depends on v or its D is not its exact df/dv: the adjoint's vhat then
  // takes the terms' velocity shares (AdjointRow::v).
  static constexpr bool kVelocityAdjoint = cloth_terms::ListTraits::kVelocityAdjoint;

  const ClothSprings& springs() const { return springs_; }
  // A's pattern and, after assemble(), its blocks (mass in kg on the diagonal).
  const BlockSparse3& matrix() const { return A_; }
  // Per block of A: whether IC(0) keeps it (the diagonal and the damped springs' blocks).
  std::vector<char> factor_pattern() const;

  // Evaluates every term at state s for a (sub)step of length h (s): f, K's and D's blocks and A.
  // `forces` false leaves f's velocity-dependent parts out (the adjoint needs the matrices alone).
  void assemble(const ClothState& s, double h, bool forces);
  const VecX& force() const { return force_; }
  // Row i of K v (3-vector) of the last assemble, the springs' part in velocity differences.
  Vec3 stiffness_times_velocity(int i, const VecX& v) const;
  // K or D of the last assemble as a matrix on A's pattern (diagnostics; allocates).
  BlockSparse3 stiffness_blocks() const;
  BlockSparse3 damping_blocks() const;

  // Adds the terms' energies (J) at state s: every part but `contact`, or (contact = true) only it.
  void add_energy(const ClothState& s, bool contact, ClothEnergy& e) const;
  // The spring terms' conservative force on spring k's end a at positions x (N).
  Vec3 conservative_spring_force(const VecX& x, int k) const;

  // Adjoint of one substep, after assemble() at its start state: first the springs' products (parallel),
  // then each particle's row, then the terms' couplings beyond the rows.
  void adjoint_springs(const ClothAdjoint& a);
  AdjointRow adjoint_row(const ClothAdjoint& a, int i) const;
  void adjoint_coupled(const ClothAdjoint& a, VecX& xhat, VecX& vhat) const;

 private:
  template <class F>
  void for_each_term(F&& f) const;
  void assemble_springs(const ClothState& s, bool forces);
  void gather_springs(int i, double h, bool forces, ParticleRow& row, Mat3& K);
  BlockSparse3 blocks(const std::vector<Mat3>& per_spring, const std::vector<Mat3>& diagonal) const;

  ClothSprings springs_;
  ClothTerms terms_;
  int p_;
  int damping_springs_ = 0;  // springs [0, this) have a damping block Bd
  BlockSparse3 A_;
  std::vector<int> slot_spring_;  // per block of A: the spring joining its row and column, -1 on the diagonal

  // Work space, sized once.
  std::vector<Vec3> spring_f_, spring_tv_;  // per spring: force on a (forward), adjoint share (backward)
  std::vector<Mat3> spring_K_, spring_D_;
  std::vector<SpringState> spring_state_;     // per spring: its geometry at the last assemble
  mutable std::vector<double> energy_parts_;  // one partial sum per fixed chunk of springs
  std::vector<Mat3> particle_K_;              // per particle: the particle terms' part of K's diagonal block
  std::vector<Mat3> diag_K_, diag_D_;         // per particle: K's and D's diagonal blocks
  VecX force_;
};

}  // namespace kf

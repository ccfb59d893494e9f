#include "sim/cloth/cloth_assembly.h"

#include <algorithm>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

namespace kf {

namespace {
using cloth_terms::ListTraits;

template <class T>
constexpr bool kSpringTerm = std::decay_t<T>::kStencil == ClothStencil::kSpring;
template <class T>
constexpr bool kParticleTerm = std::decay_t<T>::kStencil == ClothStencil::kParticle;

template <class... Ts>
std::tuple<Ts...> make_terms(std::type_identity<std::tuple<Ts...>>, const ClothTermSetup& setup) {
  return std::tuple<Ts...>{Ts(setup)...};
}

// The springs that have a damping block: the longest prefix a term with kDampingSlot acts on.
int damping_springs(const ClothTerms& terms) {
  int n = 0;
  auto visit = [&](const auto& t) {
    if constexpr (std::decay_t<decltype(t)>::kDampingSlot) n = std::max(n, t.springs());
  };
  std::apply([&](const auto&... t) { (visit(t), ...); }, terms);
  return n;
}
}  // namespace

template <class F>
void ClothAssembly::for_each_term(F&& f) const {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (f(std::get<I>(terms_), std::integral_constant<int, int(I)>{}), ...);
  }(std::make_index_sequence<std::tuple_size_v<ClothTerms>>{});
}

ClothAssembly::ClothAssembly(const ClothSpec& spec, const VecX& x0,
                             const std::vector<std::unique_ptr<Collider>>& colliders)
    : springs_(make_cloth_springs(spec, x0)),
      terms_(make_terms(std::type_identity<ClothTerms>{}, ClothTermSetup{spec, springs_, colliders})),
      p_(spec.particles()) {
  damping_springs_ = damping_springs(terms_);
  const auto& list = springs_.list;
  std::vector<std::vector<int>> cols(p_);
  for (int i = 0; i < p_; ++i) cols[i].push_back(i);
  for (const BucklingSpring& s : list) {
    cols[s.a].push_back(s.b);
    cols[s.b].push_back(s.a);
  }
  A_.set_pattern(cols);
  slot_spring_.assign(A_.nonzero_blocks(), -1);
  for (int i = 0; i < p_; ++i)
    for (int e = springs_.incident_start[i]; e < springs_.incident_start[i + 1]; ++e) {
      ClothSprings::Incident& in = springs_.incident[e];
      const BucklingSpring& s = list[in.spring];
      in.slot = A_.find(i, in.sign > 0 ? s.b : s.a);
      slot_spring_[in.slot] = in.spring;
    }
  const size_t ns = list.size();
  spring_f_.assign(ns, Vec3::Zero());
  if (ListTraits::spring_velocity_adjoint) spring_tv_.assign(ns, Vec3::Zero());
  spring_K_.assign(ns, Mat3::Zero());
  spring_D_.assign(ns, Mat3::Zero());
  spring_state_.assign(ns, SpringState());
  energy_parts_.assign((ns + kClothSpringGrain - 1) / kClothSpringGrain, 0.0);
  particle_K_.assign(p_, Mat3::Zero());
  diag_K_.assign(p_, Mat3::Zero());
  diag_D_.assign(p_, Mat3::Zero());
  force_.setZero(3 * p_);
}

std::vector<char> ClothAssembly::factor_pattern() const {
  std::vector<char> keep(A_.nonzero_blocks());
  for (int s = 0; s < A_.nonzero_blocks(); ++s) keep[s] = slot_spring_[s] < springs_.damped;  // the diagonal is -1
  return keep;
}

void ClothAssembly::assemble_springs(const ClothState& s, bool forces) {
  const int ns = int(springs_.list.size());
  tbb::parallel_for(tbb::blocked_range<int>(0, ns, kClothSpringGrain), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k < r.end(); ++k) {
      SpringSlot slot{spring_f_[k], spring_K_[k], spring_D_[k]};
      for_each_term([&](const auto& t, auto) {
        if constexpr (kSpringTerm<decltype(t)>)
          if (k < t.springs()) t.write(s, k, forces, spring_state_[k], slot);
      });
    }
  });
}

// Row i's springs: A's off-diagonal blocks are the springs' own (one spring per particle pair), so K and
// D are never stored as matrices, which keeps a 100 x 100 sheet's working set in cache.
void ClothAssembly::gather_springs(int i, double h, bool forces, ParticleRow& row, Mat3& K) {
  const auto& inc = springs_.incident;
  Vec3 f = row.f;  // in registers across the loop
  Mat3 Kii = K, D = row.D;
  for (int e = springs_.incident_start[i]; e < springs_.incident_start[i + 1]; ++e) {
    const ClothSprings::Incident& in = inc[e];
    const Mat3& Ks = spring_K_[in.spring];
    if (forces) f += in.sign * spring_f_[in.spring];
    Kii -= Ks;
    if (in.spring < damping_springs_) {
      const Mat3& Ds = spring_D_[in.spring];
      A_.block(in.slot) = -h * Ds - h * h * Ks;
      D -= Ds;
    } else {
      A_.block(in.slot) = -h * Mat3::Zero() - h * h * Ks;
    }
  }
  row.f = f;
  row.D = D;
  K = Kii;
}

void ClothAssembly::assemble(const ClothState& s, double h, bool forces) {
  assemble_springs(s, forces);
  tbb::parallel_for(tbb::blocked_range<int>(0, p_, kClothParticleGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) {
      ParticleRow row;
      Mat3 K = Mat3::Zero();  // the springs' part of K's diagonal block
      for_each_term([&](const auto& t, auto index) {
        if constexpr (kParticleTerm<decltype(t)>) t.add(s, i, forces, row);
        else if constexpr (decltype(index)::value == ListTraits::first_spring()) gather_springs(i, h, forces, row, K);
      });
      particle_K_[i] = row.K;
      K += row.K;
      diag_K_[i] = K;
      diag_D_[i] = row.D;
      seg(force_, i) = row.f;
      Mat3& Aii = A_.block(A_.diag_slot(i));
      Aii = -h * row.D - h * h * K;
      Aii += s.mass[i] * Mat3::Identity();
    }
  }, tbb::static_partitioner());
}

// K's rows sum to the particle terms' stiffness alone, so a sheet moving as a whole gives exactly no
// spring term instead of the round-off of large cancelling products (which shifted the whole sheet by
// thousands of ulps per step and set the noise floor of finite-difference checks).
Vec3 ClothAssembly::stiffness_times_velocity(int i, const VecX& v) const {
  const Vec3 vi = seg(v, i);
  Vec3 kv = particle_K_[i] * vi;
  for (int k = A_.row_start(i); k < A_.row_start(i + 1); ++k)
    if (A_.col(k) != i) kv.noalias() += spring_K_[slot_spring_[k]] * (seg(v, A_.col(k)) - vi);
  return kv;
}

BlockSparse3 ClothAssembly::blocks(const std::vector<Mat3>& per_spring, const std::vector<Mat3>& diagonal) const {
  BlockSparse3 m = A_;
  for (int i = 0; i < p_; ++i)
    for (int k = A_.row_start(i); k < A_.row_start(i + 1); ++k) {
      const int sp = slot_spring_[k];
      m.block(k) = sp < 0 ? diagonal[i] : per_spring[sp];  // spring_D_ stays zero beyond the damped springs
    }
  return m;
}

BlockSparse3 ClothAssembly::stiffness_blocks() const { return blocks(spring_K_, diag_K_); }
BlockSparse3 ClothAssembly::damping_blocks() const { return blocks(spring_D_, diag_D_); }

void ClothAssembly::add_energy(const ClothState& s, bool contact, ClothEnergy& e) const {
  for_each_term([&](const auto& t, auto) {
    using T = std::decay_t<decltype(t)>;
    if constexpr (T::kEnergy != nullptr) {
      if ((T::kEnergy == &ClothEnergy::contact) != contact) return;
      double& part = e.*T::kEnergy;
      if constexpr (kParticleTerm<T>) {
        for (int i = 0; i < p_; ++i) t.add_energy(s, i, part);
      } else {
        // In fixed chunks summed in chunk order: the same sum on any thread count.
        const int ns = int(t.springs()), chunks = (ns + kClothSpringGrain - 1) / kClothSpringGrain;
        double* parts = energy_parts_.data();  // sized for every chunk at construction
        tbb::parallel_for(tbb::blocked_range<int>(0, chunks, 1), [&](const tbb::blocked_range<int>& r) {
          for (int c = r.begin(); c < r.end(); ++c) {
            double sum = 0;
            for (int k = c * kClothSpringGrain; k < std::min(ns, (c + 1) * kClothSpringGrain); ++k)
              sum += t.energy(s.x, k);
            parts[c] = sum;
          }
        });
        for (int c = 0; c < chunks; ++c) part += parts[c];
      }
    }
  });
}

Vec3 ClothAssembly::conservative_spring_force(const VecX& x, int k) const {
  Vec3 f = Vec3::Zero();
  int found = 0;
  for_each_term([&](const auto& t, auto) {
    using T = std::decay_t<decltype(t)>;
    if constexpr (kSpringTerm<T> && T::kEnergy != nullptr)
      if (k < t.springs()) f = found++ ? Vec3(f + t.conservative_force(x, k)) : t.conservative_force(x, k);
  });
  return f;
}

void ClothAssembly::adjoint_springs(const ClothAdjoint& a) {
  const int ns = int(springs_.list.size());
  tbb::parallel_for(tbb::blocked_range<int>(0, ns, kClothSpringGrain), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k < r.end(); ++k) {
      const BucklingSpring& s = springs_.list[k];
      const Vec3 dw = seg(a.w, s.b) - seg(a.w, s.a);
      const bool derivative = a.exact && dw.squaredNorm() > 0;
      Vec3 t, tv = Vec3::Zero();  // the first spring term assigns t
      for_each_term([&](const auto& term, auto) {
        using T = std::decay_t<decltype(term)>;
        if constexpr (kSpringTerm<T>) {
          if (k >= term.springs()) return;
          term.spring_adjoint(a, k, spring_state_[k], dw, derivative, t);
          if constexpr (T::kVelocityAdjoint) term.spring_adjoint_v(a, k, spring_state_[k], dw, derivative, tv);
        }
      });
      spring_f_[k] = t;
      if constexpr (ListTraits::spring_velocity_adjoint) spring_tv_[k] = tv;
    }
  });
}

AdjointRow ClothAssembly::adjoint_row(const ClothAdjoint& a, int i) const {
  AdjointRow row;
  for_each_term([&](const auto& t, auto index) {
    if constexpr (kParticleTerm<decltype(t)>) {
      t.add_adjoint(a, i, row);
    } else if constexpr (decltype(index)::value == ListTraits::first_spring()) {
      for (int e = springs_.incident_start[i]; e < springs_.incident_start[i + 1]; ++e) {
        const ClothSprings::Incident& in = springs_.incident[e];
        row.x += in.sign * spring_f_[in.spring];
        if constexpr (ListTraits::spring_velocity_adjoint) row.v += in.sign * spring_tv_[in.spring];
      }
    }
  });
  return row;
}

void ClothAssembly::adjoint_coupled(const ClothAdjoint& a, VecX& xhat, VecX& vhat) const {
  for_each_term([&](const auto& t, auto) {
    if constexpr (kParticleTerm<decltype(t)>) t.add_adjoint_coupled(a, xhat, vhat);
  });
}

}  // namespace kf

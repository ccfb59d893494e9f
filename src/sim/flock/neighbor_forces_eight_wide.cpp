// NeighborForces' pair terms eight neighbours at a time with AVX-512: each lane evaluates one neighbour's
// terms with the scalar formulas' operations in their order (neighbor_forces.cpp), terms a scalar pass would
// skip are +0 or -0 (which leave a sum unchanged: a sum that starts at +0 never becomes -0), and the lanes are
// then added to the agent's sums one by one in list order, eight sums side by side in one vector (a chunk
// whose lanes are all off for a term adds +0 or skips it). So the sums are bit for bit the scalar passes'.
#include "sim/flock/flock_simd.h"

#ifdef KF_FLOCK_AVX512
#include <immintrin.h>

#include <algorithm>

#include "sim/flock/neighbor_pair_sums.h"

// GCC 12's AVX-512 intrinsics fill the lanes an instruction leaves alone with a self-initialised placeholder
// (_mm512_undefined_pd), which its uninitialised-use analysis reports wherever they are inlined.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

namespace kf {

namespace {

typedef __m512d V;

KF_EIGHT_WIDE inline V splat(double a) { return _mm512_set1_pd(a); }
KF_EIGHT_WIDE inline V add(V a, V b) { return _mm512_add_pd(a, b); }
KF_EIGHT_WIDE inline V sub(V a, V b) { return _mm512_sub_pd(a, b); }
KF_EIGHT_WIDE inline V mul(V a, V b) { return _mm512_mul_pd(a, b); }
// a * b, a - b and a in the lanes of `on`, +0 elsewhere.
KF_EIGHT_WIDE inline V mul_in(__mmask8 on, V a, V b) { return _mm512_maskz_mul_pd(on, a, b); }
KF_EIGHT_WIDE inline V sub_in(__mmask8 on, V a, V b) { return _mm512_maskz_sub_pd(on, a, b); }
KF_EIGHT_WIDE inline V only(__mmask8 on, V a) { return _mm512_maskz_mov_pd(on, a); }
KF_EIGHT_WIDE inline V root(V a) { return _mm512_sqrt_pd(a); }
KF_EIGHT_WIDE inline __mmask8 below(V r2, double bound) { return _mm512_cmp_pd_mask(r2, splat(bound), _CMP_LT_OQ); }

// smooth_kernel_inv of eight squared distances in the lanes of `on` ({0, 0} elsewhere): w = t t t and
// w' = -3 t t / R^2 with t = 1 - r^2 / R^2, zero where !(t > 0) fails as the scalar code's `t <= 0` test does.
struct Kernel8 {
  V w, dw;
};
KF_EIGHT_WIDE inline Kernel8 kernel8(V r2, double inv_radius2, __mmask8 on) {
  const V inv = splat(inv_radius2), t = sub(splat(1.0), mul(r2, inv));
  const __mmask8 m = on & _mm512_cmp_pd_mask(t, _mm512_setzero_pd(), _CMP_NLE_UQ);
  return {mul_in(m, mul(t, t), t), mul_in(m, mul(mul(splat(-3.0), t), t), inv)};
}

// The (x, z) lanes of a pair term interleaved, so lane l's pair is out[2 l], out[2 l + 1].
KF_EIGHT_WIDE inline void store_pairs(V x, V z, double* out) {
  _mm512_store_pd(out, _mm512_permutex2var_pd(x, _mm512_setr_epi64(0, 8, 1, 9, 2, 10, 3, 11), z));
  _mm512_store_pd(out + 8, _mm512_permutex2var_pd(x, _mm512_setr_epi64(4, 12, 5, 13, 6, 14, 7, 15), z));
}
KF_EIGHT_WIDE inline Pair2 pair_at(const double* pairs, int l) { return Pair2(_mm_load_pd(pairs + 2 * l)); }

// The next (up to) eight list entries from s: which lanes hold one, and their agents (agent 0 in lanes past
// the list's end, whose terms are masked off).
struct Chunk {
  int count;
  __mmask8 lanes;
  alignas(32) int agent[8];
};
KF_EIGHT_WIDE inline Chunk chunk(std::span<const int> nbrs, int s) {
  Chunk k;
  k.count = std::min(8, int(nbrs.size()) - s);
  k.lanes = __mmask8((1u << k.count) - 1);
  _mm256_store_si256(reinterpret_cast<__m256i*>(k.agent), _mm256_maskz_loadu_epi32(k.lanes, nbrs.data() + s));
  return k;
}

// Each agent's record is read whole (one or two cache lines, where gathering its fields one by one costs a
// load per field) and the eight records transposed into one lane vector per field.

// x, z, vx, vz of the chunk's agents.
struct Motion8 {
  V x, z, vx, vz;
};
KF_EIGHT_WIDE inline Motion8 motion8(const AgentMotion* a, const Chunk& k) {
  V r[4];  // agents l and l + 4
  for (int l = 0; l < 4; ++l)
    r[l] = _mm512_insertf64x4(_mm512_castpd256_pd512(_mm256_loadu_pd(&a[k.agent[l]].x)),
                              _mm256_loadu_pd(&a[k.agent[l + 4]].x), 1);
  const V xv01 = _mm512_unpacklo_pd(r[0], r[1]), zw01 = _mm512_unpackhi_pd(r[0], r[1]);
  const V xv23 = _mm512_unpacklo_pd(r[2], r[3]), zw23 = _mm512_unpackhi_pd(r[2], r[3]);
  const __m512i first = _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13),
                second = _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15);
  return {_mm512_permutex2var_pd(xv01, first, xv23), _mm512_permutex2var_pd(zw01, first, zw23),
          _mm512_permutex2var_pd(xv01, second, xv23), _mm512_permutex2var_pd(zw01, second, zw23)};
}

// out[l] = lane l of in[0], ..., in[7]: the 8 x 8 transpose, both ways (records to fields, terms to records).
KF_EIGHT_WIDE inline void transpose8(const V in[8], V out[8]) {
  V t[8], u[8];
  for (int l = 0; l < 8; l += 2) {
    t[l] = _mm512_unpacklo_pd(in[l], in[l + 1]);      // lanes 0, 2, 4, 6 of in[l], in[l + 1]
    t[l + 1] = _mm512_unpackhi_pd(in[l], in[l + 1]);  // lanes 1, 3, 5, 7
  }
  for (int h = 0; h < 8; h += 4)
    for (int odd = 0; odd < 2; ++odd) {
      u[h + odd * 2] = _mm512_shuffle_f64x2(t[h + odd], t[h + 2 + odd], 0x88);      // lanes odd, odd + 4
      u[h + odd * 2 + 1] = _mm512_shuffle_f64x2(t[h + odd], t[h + 2 + odd], 0xdd);  // odd + 2, odd + 6
    }
  for (int g = 0; g < 4; ++g) {  // u[g] and u[g + 4] hold lanes b and b + 4, b = (g / 2) + 2 (g % 2)
    const int b = g / 2 + 2 * (g % 2);
    out[b] = _mm512_shuffle_f64x2(u[g], u[g + 4], 0x88);
    out[b + 4] = _mm512_shuffle_f64x2(u[g], u[g + 4], 0xdd);
  }
}

// The first eight fields of the chunk's agents (x, z, vx, vz, yx, yz, ox, oz), then c/b and q.
struct Adjoint8 {
  V f[8], c_over_b, q;
};
KF_EIGHT_WIDE inline Adjoint8 adjoint8(const AgentAdjoint* a, const Chunk& k, bool with_q) {
  V r[8];
  for (int l = 0; l < 8; ++l) r[l] = _mm512_loadu_pd(&a[k.agent[l]].x);
  Adjoint8 out;
  transpose8(r, out.f);
  // (c/b, q) of agents 0-3 and 4-7, two by two (loads where gathers are slow on some cores).
  const auto tail_of = [&](int l) { return _mm_loadu_pd(&a[k.agent[l]].c_over_b); };
  V tail[2];
  for (int h = 0; h < 8; h += 4)
    tail[h / 4] = _mm512_insertf64x4(_mm512_castpd256_pd512(_mm256_set_m128d(tail_of(h + 1), tail_of(h))),
                                     _mm256_set_m128d(tail_of(h + 3), tail_of(h + 2)), 1);
  out.c_over_b = _mm512_permutex2var_pd(tail[0], _mm512_setr_epi64(0, 2, 4, 6, 8, 10, 12, 14), tail[1]);
  out.q = with_q ? _mm512_permutex2var_pd(tail[0], _mm512_setr_epi64(1, 3, 5, 7, 9, 11, 13, 15), tail[1])
                 : _mm512_setzero_pd();
  return out;
}

// Eight of an agent's sums side by side: each neighbour's eight terms are transposed into one vector and
// added to them whole, lane by lane the same additions in the same order as one sum at a time.
KF_EIGHT_WIDE inline V add_lanes_in_order(V sums, const V terms[8], int count) {
  V record[8];
  transpose8(terms, record);
  for (int l = 0; l < count; ++l) sums = add(sums, record[l]);
  return sums;
}

}  // namespace

// forward_matching_centering over every neighbour, forward_avoidance over those within its radius. The sums
// side by side: m, c, a (which adds -g d: a - t is a + -t), wm, w.
KF_EIGHT_WIDE void NeighborForces::forward_eight_wide(const AgentMotion* a, std::span<const int> nbrs, int i,
                                                      ForwardSum& sum) const {
  const AgentMotion& ai = a[i];
  const V xi = splat(ai.x), zi = splat(ai.z), vxi = splat(ai.vx), vzi = splat(ai.vz);
  V sums = _mm512_setr_pd(sum.m[0], sum.m[1], sum.c[0], sum.c[1], sum.a[0], sum.a[1], sum.wm, sum.w);
  V terms[8];
  for (int s = 0; s < int(nbrs.size()); s += 8) {
    const Chunk k = chunk(nbrs, s);
    const Motion8 n = motion8(a, k);
    const V px = sub(n.x, xi), pz = sub(n.z, zi);
    const V r2 = add(mul(px, px), mul(pz, pz));
    const __mmask8 in_m = k.lanes & below(r2, rm2_), in_c = k.lanes & below(r2, rc2_), in_a = k.lanes & below(r2, ra2_);
    const V w_m = kernel8(r2, inv_rm2_, in_m).w;
    terms[0] = mul_in(in_m, w_m, sub(n.vx, vxi));
    terms[1] = mul_in(in_m, w_m, sub(n.vz, vzi));
    terms[6] = w_m;
    const V w_c = same_mc_ ? w_m : kernel8(r2, inv_rc2_, in_c).w;
    terms[2] = mul_in(in_c, w_c, px);
    terms[3] = mul_in(in_c, w_c, pz);
    terms[7] = w_c;
    // A chunk with no lane inside avoidance's radius skips it: its terms would all be +0 (0 - +0 is +0
    // too), which leave the sum as it is.
    if (in_a) {
      const V g = _mm512_div_pd(kernel8(r2, inv_ra2_, in_a).w, root(add(r2, splat(eps2_))));
      terms[4] = sub_in(in_a, _mm512_setzero_pd(), mul(g, px));
      terms[5] = sub_in(in_a, _mm512_setzero_pd(), mul(g, pz));
    } else {
      terms[4] = terms[5] = _mm512_setzero_pd();
    }
    sums = add_lanes_in_order(sums, terms, k.count);
  }
  alignas(64) double out[8];
  _mm512_store_pd(out, sums);
  sum.m = pair(out[0], out[1]);
  sum.c = pair(out[2], out[3]);
  sum.a = pair(out[4], out[5]);
  sum.wm = out[6];
  sum.w = out[7];
}

// transposed_matching_centering over every neighbour, transposed_avoidance over those within its radius;
// d = x_j - x_i, e = y_j - y_i. The sums side by side: km, dm, kc, ka; kq apart.
template <bool kSummedWeights>
KF_EIGHT_WIDE void NeighborForces::transposed_eight_wide(const AgentAdjoint* a, std::span<const int> nbrs, int j,
                                                         TransposedSum& sum) const {
  const AgentAdjoint& aj = a[j];
  const V xj = splat(aj.x), zj = splat(aj.z), vxj = splat(aj.vx), vzj = splat(aj.vz), yxj = splat(aj.yx),
          yzj = splat(aj.yz), oxj = splat(aj.ox), ozj = splat(aj.oz), cbj = splat(aj.c_over_b), qj = splat(aj.q);
  V sums = _mm512_setr_pd(sum.km[0], sum.km[1], sum.dm[0], sum.dm[1], sum.kc[0], sum.kc[1], sum.ka[0], sum.ka[1]);
  V terms[8];
  alignas(64) double kq[16];
  for (int s = 0; s < int(nbrs.size()); s += 8) {
    const Chunk k = chunk(nbrs, s);
    const Adjoint8 n = adjoint8(a, k, kSummedWeights);
    const V dx = sub(xj, n.f[0]), dz = sub(zj, n.f[1]), r2 = add(mul(dx, dx), mul(dz, dz));
    const V yxi = n.f[4], yzi = n.f[5], ex = sub(yxj, yxi), ez = sub(yzj, yzi);
    const __mmask8 in_m = k.lanes & below(r2, rm2_), in_c = k.lanes & below(r2, rc2_), in_a = k.lanes & below(r2, ra2_);
    // Matching: K^T 2 w' ((v_i - v_j) . e) d, D^T w (y_i - y_j), and the summed weights' 2 w' (q_i + q_j) d.
    const Kernel8 wm = kernel8(r2, inv_rm2_, in_m);
    const V dw2 = mul(splat(2.0), wm.dw);
    const V sm = mul(dw2, add(mul(sub(n.f[2], vxj), ex), mul(sub(n.f[3], vzj), ez)));
    terms[0] = mul_in(in_m, sm, dx);
    terms[1] = mul_in(in_m, sm, dz);
    terms[2] = mul_in(in_m, wm.w, sub(yxi, yxj));
    terms[3] = mul_in(in_m, wm.w, sub(yzi, yzj));
    if constexpr (kSummedWeights) {
      const V sq = mul(dw2, add(n.q, qj));
      store_pairs(mul_in(in_m, sq, dx), mul_in(in_m, sq, dz), kq);
    }
    // Centering: c/b_i (w y_i + s_i g) - c/b_j (w y_j - s_j g), g = -2 w' d.
    const Kernel8 wc = same_mc_ ? wm : kernel8(r2, inv_rc2_, in_c);
    const V gw = mul(splat(-2.0), wc.dw), gx = mul(gw, dx), gz = mul(gw, dz);
    const V si = add(mul(sub(n.f[6], dx), yxi), mul(sub(n.f[7], dz), yzi));
    const V sj = add(mul(add(dx, oxj), yxj), mul(add(dz, ozj), yzj));
    const V cbi = n.c_over_b;
    terms[4] = sub_in(in_c, mul(cbi, add(mul(wc.w, yxi), mul(si, gx))), mul(cbj, sub(mul(wc.w, yxj), mul(sj, gx))));
    terms[5] = sub_in(in_c, mul(cbi, add(mul(wc.w, yzi), mul(si, gz))), mul(cbj, sub(mul(wc.w, yzj), mul(sj, gz))));
    // Avoidance: w g e + 2 (w' g - w g^3 / 2) (d . e) d, g = (r^2 + eps^2)^-1/2; skipped like the forward's
    // when no lane is inside its radius (+0 terms).
    if (in_a) {
      const Kernel8 wa = kernel8(r2, inv_ra2_, in_a);
      const V g = _mm512_div_pd(splat(1.0), root(add(r2, splat(eps2_)))), wg = mul(wa.w, g);
      const V sa = mul(mul(splat(2.0), sub(mul(wa.dw, g), mul(mul(mul(mul(splat(0.5), wa.w), g), g), g))),
                       add(mul(dx, ex), mul(dz, ez)));
      terms[6] = only(in_a, add(mul(wg, ex), mul(sa, dx)));
      terms[7] = only(in_a, add(mul(wg, ez), mul(sa, dz)));
    } else {
      terms[6] = terms[7] = _mm512_setzero_pd();
    }
    sums = add_lanes_in_order(sums, terms, k.count);
    if constexpr (kSummedWeights)
      for (int l = 0; l < k.count; ++l) sum.kq += pair_at(kq, l);
  }
  alignas(64) double out[8];
  _mm512_store_pd(out, sums);
  sum.km = pair(out[0], out[1]);
  sum.dm = pair(out[2], out[3]);
  sum.kc = pair(out[4], out[5]);
  sum.ka = pair(out[6], out[7]);
}

template void NeighborForces::transposed_eight_wide<false>(const AgentAdjoint*, std::span<const int>, int,
                                                           TransposedSum&) const;
template void NeighborForces::transposed_eight_wide<true>(const AgentAdjoint*, std::span<const int>, int,
                                                          TransposedSum&) const;

}  // namespace kf

#endif  // KF_FLOCK_AVX512

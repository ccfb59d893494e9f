#include "sim/flock/neighbor_grid.h"

#include <algorithm>
#include <climits>
#include <cmath>

#include "core/check.h"
#include "sim/flock/flock_simd.h"
#ifdef KF_FLOCK_AVX512
#include <immintrin.h>
#endif
#include "sim/flock/parallel_agents.h"

namespace kf {

namespace {

// Cell index of one coordinate; non-finite or absurdly far positions land in a clamped cell (the
// simulation reports them as diverged anyway) so the conversion to an integer is always defined.
int64_t cell_index(double c, double inv_cell) {
  double q = std::floor(c * inv_cell);
  if (!(q > -1e15)) q = -1e15;  // also catches NaN
  if (q > 1e15) q = 1e15;
  return int64_t(q);
}

#ifdef KF_FLOCK_AVX512
// Candidates s in [s, e) of an unwrapped run within r2 of (xi, zi), other than slot k, appended to out from
// entry n, eight at a time (the run's last few masked) while eight more fit below cap; returns the new n and
// advances s past those tested (the caller's scalar loop takes any left: a list about to outgrow out). Lanes are
// compressed in order, so the list is the scalar loop's (flock_simd.h).
KF_EIGHT_WIDE int gather_eight_at_a_time(const double* px, const double* pz, double xi, double zi, double r2, int k,
                                         int& s, int e, int cap, int* out, int n) {
  const __m512d vx = _mm512_set1_pd(xi), vz = _mm512_set1_pd(zi), vr2 = _mm512_set1_pd(r2);
  const __m256i vk = _mm256_set1_epi32(k), eight = _mm256_set1_epi32(8);
  __m256i slot = _mm256_add_epi32(_mm256_set1_epi32(s), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
  for (; s < e && n + 8 <= cap; s += 8) {
    const __mmask8 lanes = e - s >= 8 ? __mmask8(0xff) : __mmask8((1u << (e - s)) - 1);  // the run's last few
    const __m512d ex = _mm512_sub_pd(_mm512_maskz_loadu_pd(lanes, px + s), vx);
    const __m512d ez = _mm512_sub_pd(_mm512_maskz_loadu_pd(lanes, pz + s), vz);
    const __m512d d2 = _mm512_add_pd(_mm512_mul_pd(ex, ex), _mm512_mul_pd(ez, ez));
    const __mmask8 hit = _mm512_cmp_pd_mask(d2, vr2, _CMP_LT_OQ) & ~_mm256_cmpeq_epi32_mask(slot, vk) & lanes;
    // Compressed in a register and stored whole (entries past the hits are overwritten later or unused; n + 8
    // <= cap keeps them in the buffer): a compressing store to memory is microcoded and slow on some cores.
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + n), _mm256_maskz_compress_epi32(hit, slot));
    n += __builtin_popcount(unsigned(hit));
    slot = _mm256_add_epi32(slot, eight);
  }
  return n;
}
#endif

}  // namespace

template <bool kWrapped>
int NeighborGrid::gather_run(int k, int s, int e, int64_t cx0, int64_t cz, double r2, int cap, int* out, int n) const {
  // Branch-free: every candidate is written to the next free entry (or the scratch one) and counted when
  // within the radius and not k, and in a wrapped table only when in one of the run's cells (a bucket
  // then holds cells far apart).
  const double xi = sorted_px_[k], zi = sorted_pz_[k];
#ifdef KF_FLOCK_AVX512
  if constexpr (!kWrapped) {
    if (flock_simd_enabled())
      n = gather_eight_at_a_time(sorted_px_.data(), sorted_pz_.data(), xi, zi, r2, k, s, e, cap, out, n);
  }
#endif
  for (; s < e; ++s) {
    const double ex = sorted_px_[s] - xi, ez = sorted_pz_[s] - zi;
    bool hit = (ex * ex + ez * ez < r2) & (s != k);
    if constexpr (kWrapped) hit &= (sorted_cz_[s] == cz) & (uint64_t(sorted_cx_[s] - cx0) <= 2 * kReach);
    out[n < cap ? n : cap] = s;
    n += int(hit);
  }
  return n;
}

template <bool kWrapped>
int NeighborGrid::gather(int k, double r2, int cap, int* out) const {
  const int64_t cx = sorted_cx_[k], cz = sorted_cz_[k];
  int n = 0;
  for (int64_t row = cz - kReach; row <= cz + kReach; ++row) {
    if ((uint64_t(cx - kReach - origin_x_) & column_mask_) + 2 * kReach <= column_mask_) {  // consecutive buckets
      const uint64_t b = bucket_of(cx - kReach, row);
      n = gather_run<kWrapped>(k, bucket_start_[b], bucket_start_[b + 2 * kReach + 1], cx - kReach, row, r2, cap, out,
                               n);
      continue;
    }
    for (int64_t c = cx - kReach; c <= cx + kReach; ++c) {  // the row wraps: one cell at a time, in column order
      const uint64_t b = bucket_of(c, row);
      n = gather_run<true>(k, bucket_start_[b], bucket_start_[b + 1], c, row, r2, cap, out, n);
    }
  }
  return n;
}

void NeighborGrid::search(const VecX& x, double radius, NeighborLists& out) {
  index(x, radius);
  const int p = int(sorted_.size());
  gather_into_slabs(p);
  compact_slabs(p, out);
}

void NeighborGrid::index(const VecX& x, double radius) {
  const int p = int(x.size() / 3);
  if (int(cell_x_.size()) != p) size_for(p);
  r2_ = radius * radius;
  sort_into_buckets(x, radius, p);
}

int NeighborGrid::neighbors_of_slot(int slot, std::vector<int>& out) const {
  for (;;) {  // at most twice: a first gather that overflows says how many there are
    if (out.size() < 2) out.resize(64);
    const int cap = int(out.size()) - 1;
    const int n = wrapped_ ? gather<true>(slot, r2_, cap, out.data()) : gather<false>(slot, r2_, cap, out.data());
    if (n <= cap) return n;
    out.resize(size_t(n) + size_t(n) / 2 + 2);
  }
}

void NeighborGrid::size_for(int p) {
  int buckets = 16;
  while (buckets < 4 * p) buckets *= 2;
  buckets_ = buckets;
  cell_x_.assign(p, 0);
  cell_z_.assign(p, 0);
  bucket_of_agent_.assign(p, 0);
  bucket_start_.assign(buckets + 1, 0);
  bucket_cursor_.assign(buckets, 0);
  sorted_.assign(p, 0);
  slot_of_agent_.assign(p, 0);
  sorted_cx_.assign(p, 0);
  sorted_cz_.assign(p, 0);
  sorted_px_.assign(p, 0.0);
  sorted_pz_.assign(p, 0.0);
  count_.assign(p, 0);
}

void NeighborGrid::fit_table(int p) {
  int64_t x0 = INT64_MAX, x1 = INT64_MIN, z0 = INT64_MAX, z1 = INT64_MIN;
  for (int i = 0; i < p; ++i) {
    x0 = std::min(x0, cell_x_[i]);
    x1 = std::max(x1, cell_x_[i]);
    z0 = std::min(z0, cell_z_[i]);
    z1 = std::max(z1, cell_z_[i]);
  }
  if (p == 0) x0 = x1 = z0 = z1 = 0;
  // A margin of kReach cells on each side, so a box that fits is never wrapped by a neighbour's cell either.
  origin_x_ = x0 - kReach;
  origin_z_ = z0 - kReach;
  const uint64_t width = uint64_t(x1 - x0) + 2 * kReach + 1, depth = uint64_t(z1 - z0) + 2 * kReach + 1;
  uint64_t columns = 1;
  int shift = 0;
  while (columns < width && columns < uint64_t(buckets_)) columns *= 2, ++shift;
  column_mask_ = columns - 1;
  row_mask_ = uint64_t(buckets_) / columns - 1;
  row_shift_ = shift;
  wrapped_ = columns < width || row_mask_ + 1 < depth;
}

void NeighborGrid::sort_into_buckets(const VecX& x, double radius, int p) {
  const double inv_cell = kReach / radius;
  parallel_agents(p, [&](int i) {
    cell_x_[i] = cell_index(x[3 * i], inv_cell);
    cell_z_[i] = cell_index(x[3 * i + 2], inv_cell);
  });
  fit_table(p);
  parallel_agents(p, [&](int i) { bucket_of_agent_[i] = int(bucket_of(cell_x_[i], cell_z_[i])); });

  // Counting sort by bucket (serial: O(p) and deterministic); agents are scattered in increasing
  // order so every bucket lists its agents sorted.
  std::fill(bucket_start_.begin(), bucket_start_.end(), 0);
  for (int i = 0; i < p; ++i) ++bucket_start_[bucket_of_agent_[i] + 1];
  for (size_t b = 1; b < bucket_start_.size(); ++b) bucket_start_[b] += bucket_start_[b - 1];
  std::copy_n(bucket_start_.data(), buckets_, bucket_cursor_.data());
  for (int i = 0; i < p; ++i) {
    const int s = bucket_cursor_[bucket_of_agent_[i]]++;
    sorted_[s] = i;
    slot_of_agent_[i] = s;
    sorted_cx_[s] = cell_x_[i];
    sorted_cz_[s] = cell_z_[i];
    sorted_px_[s] = x[3 * i];
    sorted_pz_[s] = x[3 * i + 2];
  }
}

void NeighborGrid::gather_into_slabs(int p) {
  // One pass in bucket order: each agent writes into its own slab of `capacity_` entries; in the rare
  // search where some agent has more neighbours than ever before, the slabs grow and the pass runs again.
  if (capacity_ == 0) capacity_ = 16;
  for (;;) {
    const size_t stride = size_t(capacity_) + 1;
    if (slab_.size() < size_t(p) * stride) slab_.resize(size_t(p) * stride);
    const int cap = capacity_;
    parallel_agents(p, [&](int k) {
      const int i = sorted_[k];
      int* slab = slab_.data() + size_t(i) * stride;
      count_[i] = wrapped_ ? gather<true>(k, r2_, cap, slab) : gather<false>(k, r2_, cap, slab);
    });
    const int most = p ? *std::max_element(count_.begin(), count_.end()) : 0;
    if (most <= capacity_) break;
    capacity_ = most + most / 2 + 4;
  }
}

void NeighborGrid::compact_slabs(int p, NeighborLists& out) const {
  out.start_.resize(p + 1);
  int64_t total = 0;
  for (int i = 0; i < p; ++i) {
    out.start_[i] = int(total);
    total += count_[i];
  }
  CHECK_LE(total, int64_t(INT_MAX));
  out.start_[p] = int(total);
  out.entries_.resize(size_t(total));
  parallel_agents(p, [&](int i) {
    const int* slab = slab_.data() + size_t(i) * (size_t(capacity_) + 1);
    int* entries = out.entries_.data() + out.start_[i];
    for (int e = 0; e < count_[i]; ++e) entries[e] = sorted_[slab[e]];
  });
}

}  // namespace kf

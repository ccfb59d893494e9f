#include "sim/flock/neighbor_grid.h"

#include <algorithm>
#include <climits>
#include <cmath>

#include "core/check.h"
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

uint64_t mix(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace

uint64_t NeighborGrid::bucket_of(int64_t cx, int64_t cz) const {
  return mix(uint64_t(cx) * 0x9E3779B97F4A7C15ULL ^ mix(uint64_t(cz))) & bucket_mask_;
}

int NeighborGrid::gather(int k, double r2, int cap, int* out) const {
  const int i = sorted_[k];
  const double xi = sorted_px_[k], zi = sorted_pz_[k];
  int n = 0;
  for (int64_t dz = -1; dz <= 1; ++dz)
    for (int64_t dx = -1; dx <= 1; ++dx) {
      const int64_t cx = sorted_cx_[k] + dx, cz = sorted_cz_[k] + dz;
      const uint64_t b = bucket_of(cx, cz);
      for (int s = bucket_start_[b], e = bucket_start_[b + 1]; s < e; ++s) {
        // Buckets are shared by colliding cells: keep only agents of this exact cell.
        if (sorted_cx_[s] != cx || sorted_cz_[s] != cz) continue;
        const double ex = sorted_px_[s] - xi, ez = sorted_pz_[s] - zi;
        if (ex * ex + ez * ez < r2 && sorted_[s] != i) {
          if (n < cap) out[n] = sorted_[s];
          ++n;
        }
      }
    }
  return n;
}

void NeighborGrid::search(const VecX& x, double radius, NeighborLists& out) {
  const int p = int(x.size() / 3);
  if (int(cell_x_.size()) != p) size_for(p);
  sort_into_buckets(x, radius, p);
  gather_into_slabs(radius * radius, p);
  compact_slabs(p, out);
}

void NeighborGrid::size_for(int p) {
  size_t buckets = 1;
  while (buckets < size_t(2 * p)) buckets *= 2;
  bucket_mask_ = buckets - 1;
  cell_x_.assign(p, 0);
  cell_z_.assign(p, 0);
  bucket_start_.assign(buckets + 1, 0);
  bucket_cursor_.assign(buckets, 0);
  sorted_.assign(p, 0);
  sorted_cx_.assign(p, 0);
  sorted_cz_.assign(p, 0);
  sorted_px_.assign(p, 0.0);
  sorted_pz_.assign(p, 0.0);
  count_.assign(p, 0);
}

void NeighborGrid::sort_into_buckets(const VecX& x, double radius, int p) {
  const double inv_cell = 1.0 / radius;
  parallel_agents(p, [&](int i) {
    cell_x_[i] = cell_index(x[3 * i], inv_cell);
    cell_z_[i] = cell_index(x[3 * i + 2], inv_cell);
  });

  // Counting sort by bucket (serial: O(p) and deterministic); agents are scattered in increasing
  // order so every bucket lists its agents sorted.
  std::fill(bucket_start_.begin(), bucket_start_.end(), 0);
  for (int i = 0; i < p; ++i) ++bucket_start_[bucket_of(cell_x_[i], cell_z_[i]) + 1];
  for (size_t b = 1; b < bucket_start_.size(); ++b) bucket_start_[b] += bucket_start_[b - 1];
  std::copy(bucket_start_.begin(), bucket_start_.end() - 1, bucket_cursor_.begin());
  for (int i = 0; i < p; ++i) {
    const int s = bucket_cursor_[bucket_of(cell_x_[i], cell_z_[i])]++;
    sorted_[s] = i;
    sorted_cx_[s] = cell_x_[i];
    sorted_cz_[s] = cell_z_[i];
    sorted_px_[s] = x[3 * i];
    sorted_pz_[s] = x[3 * i + 2];
  }
}

void NeighborGrid::gather_into_slabs(double r2, int p) {
  // One pass in bucket order: each agent writes into its own slab of `capacity_` entries; in the rare
  // search where some agent has more neighbours than ever before, the slabs grow and the pass runs again.
  if (capacity_ == 0) capacity_ = 16;
  for (;;) {
    if (slab_.size() < size_t(p) * capacity_) slab_.resize(size_t(p) * capacity_);
    const int cap = capacity_;
    parallel_agents(p, [&](int k) {
      const int i = sorted_[k];
      count_[i] = gather(k, r2, cap, slab_.data() + size_t(i) * cap);
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
    std::copy_n(slab_.data() + size_t(i) * capacity_, count_[i], out.entries_.data() + out.start_[i]);
  });
}

}  // namespace kf

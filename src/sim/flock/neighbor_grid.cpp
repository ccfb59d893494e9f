#include "sim/flock/neighbor_grid.h"

#include <algorithm>
#include <cmath>

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

template <class Visit>
void NeighborGrid::for_each_neighbor(const VecX& x, int i, Visit&& visit) const {
  const double r2 = radius_ * radius_;
  const Vec3 xi = seg(x, i);
  for (int64_t dz = -1; dz <= 1; ++dz)
    for (int64_t dx = -1; dx <= 1; ++dx) {
      const int64_t cx = cell_x_[i] + dx, cz = cell_z_[i] + dz;
      const uint64_t b = bucket_of(cx, cz);
      for (int k = bucket_start_[b]; k < bucket_start_[b + 1]; ++k) {
        const int j = sorted_[k];
        // Buckets are shared by colliding cells: keep only agents of this exact cell.
        if (j == i || cell_x_[j] != cx || cell_z_[j] != cz) continue;
        if ((seg(x, j) - xi).squaredNorm() < r2) visit(j);
      }
    }
}

void NeighborGrid::build(const VecX& x, double radius) {
  const int p = int(x.size() / 3);
  radius_ = radius;
  if (int(cell_x_.size()) != p) {
    size_t buckets = 1;
    while (buckets < size_t(2 * p)) buckets *= 2;
    bucket_mask_ = buckets - 1;
    cell_x_.assign(p, 0);
    cell_z_.assign(p, 0);
    bucket_start_.assign(buckets + 1, 0);
    bucket_cursor_.assign(buckets, 0);
    sorted_.assign(p, 0);
    neighbor_count_.assign(p, 0);
  }
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
  for (int i = 0; i < p; ++i) sorted_[bucket_cursor_[bucket_of(cell_x_[i], cell_z_[i])]++] = i;

  // One pass: each agent writes into its own slab of `capacity_` entries; in the rare step where some
  // agent has more neighbours than ever before, the slabs grow and the pass runs again.
  if (capacity_ == 0) capacity_ = 16;
  for (;;) {
    if (neighbors_.size() < size_t(p) * capacity_) neighbors_.resize(size_t(p) * capacity_);
    parallel_agents(p, [&](int i) {
      int* out = neighbors_.data() + size_t(i) * capacity_;
      int n = 0;
      const int cap = capacity_;
      for_each_neighbor(x, i, [&](int j) {
        if (n < cap) out[n] = j;
        ++n;
      });
      neighbor_count_[i] = n;
    });
    const int most = p ? *std::max_element(neighbor_count_.begin(), neighbor_count_.end()) : 0;
    if (most <= capacity_) break;
    capacity_ = most + most / 2 + 4;
  }
}

}  // namespace kf

#pragma once
// Fixed-radius neighbour lists for agents on the ground plane, by a hashed uniform grid.
//
// Cells are `radius` wide in x and z and hashed into a table of ~2p buckets (filled by a counting sort),
// so memory is linear in agents however far the flock spreads. Cost is linear in agents at bounded
// density. After the first build with a given p nothing is allocated, except that the per-agent
// neighbour slabs grow (amortised) if the flock becomes denser than ever before.
#include <cstdint>
#include <span>
#include <vector>

#include "core/types.h"

namespace kf {

class NeighborGrid {
 public:
  // x: 3p positions (m). Afterwards neighbors(i) lists every j != i with |x_i - x_j|^2 < radius^2,
  // in an order that depends only on x (not on the thread count).
  void build(const VecX& x, double radius);

  int agents() const { return int(neighbor_count_.size()); }
  std::span<const int> neighbors(int i) const {
    return {neighbors_.data() + size_t(i) * capacity_, size_t(neighbor_count_[i])};
  }
  double radius() const { return radius_; }

 private:
  template <class Visit>
  void for_each_neighbor(const VecX& x, int i, Visit&& visit) const;
  uint64_t bucket_of(int64_t cx, int64_t cz) const;

  double radius_ = 0;
  uint64_t bucket_mask_ = 0;
  std::vector<int64_t> cell_x_, cell_z_;  // per agent
  std::vector<int> bucket_start_;         // buckets + 1
  std::vector<int> bucket_cursor_;        // buckets
  std::vector<int> sorted_;               // agents ordered by bucket
  std::vector<int> neighbor_count_;       // per agent
  int capacity_ = 0;                      // neighbour slots per agent
  std::vector<int> neighbors_;            // p slabs of capacity_ entries
};

}  // namespace kf
